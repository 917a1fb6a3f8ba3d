# gale.compile / Expression.eval against `gale eval --points` on the same points: the same
# numbers in float and in double, vector and scalar results, parameters, t and frame.
import csv

import numpy as np
import pytest

import gale
from conftest import run_gale

WIND = """$speed = 5;  # 0, 40
$dir = [1, 0.2, 0.3];
v = $speed * norm($dir) * (0.6 + 0.4 * fbm($P * 0.7 + [0, 0, $t]));
v + curlnoise($P + $frame * 0.01) * 0.5
"""


def write_points(path, P):
    with open(path, "w") as f:
        f.write("x,y,z\n")
        for x, y, z in P:
            f.write(f"{x!r},{y!r},{z!r}\n")  # repr: the exact double


def read_columns(path, names):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return np.array([[float(r[n]) for n in names] for r in rows])


@pytest.fixture
def points():
    rng = np.random.default_rng(7)
    return rng.uniform(-3, 3, size=(500, 3))


@pytest.mark.parametrize("precision", ["float", "double"])
def test_vector_eval_equals_gale_eval_points(tmp_path, gale_bin, points, precision):
    (tmp_path / "wind.se").write_text(WIND)
    write_points(tmp_path / "p.csv", points)
    run_gale(gale_bin, "eval", tmp_path / "wind.se", "--points", tmp_path / "p.csv", "-o", tmp_path / "o.csv",
             "--time", "0.75", "--set", "speed=7.5", "--precision", precision)
    want = read_columns(tmp_path / "o.csv", ["vx", "vy", "vz"])
    e = gale.compile(str(tmp_path / "wind.se"))
    got = e.eval(points, t=0.75, params={"speed": 7.5}, precision=precision)
    assert got.shape == (500, 3)
    assert got.dtype == (np.float32 if precision == "float" else np.float64)
    # gale eval writes the shortest text that reads back as the same float/double: exact once
    # read as that type.
    np.testing.assert_array_equal(got, want.astype(got.dtype))
    # float32 input gives the same as its float64 widening, and a strided view the same as a copy.
    np.testing.assert_array_equal(e.eval(points.astype(np.float32), t=0.75, params={"speed": 7.5}, precision=precision),
                                  e.eval(points.astype(np.float32).astype(np.float64), t=0.75,
                                         params={"speed": 7.5}, precision=precision))
    wide = np.zeros((500, 6))
    wide[:, ::2] = points
    view = wide[:, ::2]
    assert not view.flags.c_contiguous
    np.testing.assert_array_equal(e.eval(view, t=0.75, params={"speed": 7.5}, precision=precision), got)


def test_scalar_eval_frame_and_defaults(tmp_path, gale_bin, points):
    src = "$gain = 2; # 0, 4\n$gain * sin($P[0] + $frame * 0.1) + $t"
    write_points(tmp_path / "p.csv", points)
    run_gale(gale_bin, "eval", "-e", src, "--points", tmp_path / "p.csv", "-o", tmp_path / "o.csv", "--frame", "12")
    want = read_columns(tmp_path / "o.csv", ["value"])[:, 0]
    e = gale.compile(source=src)
    got = e.eval(points, frame=12)
    assert got.shape == (500,)
    np.testing.assert_array_equal(got, want.astype(np.float32))
    # $t defaults from frame through fps (24): frame 12 is t = 0.5, as gale eval's --frame.
    np.testing.assert_allclose(got, 2 * np.sin(points[:, 0] + 1.2) + 0.5, rtol=2e-6, atol=2e-6)
    assert e.params == {"gain": {"value": 2.0, "min": 0.0, "max": 4.0}}
    assert e.width == 1


def test_input_is_not_copied_and_empty_arrays_work():
    e = gale.compile(source="$P * 2")
    P = np.arange(12, dtype=np.float64).reshape(4, 3)
    np.testing.assert_array_equal(e.eval(P, precision="double"), P * 2)
    assert e.eval(np.zeros((0, 3))).shape == (0, 3)


@pytest.mark.parametrize("threads", [1, 0, 3])
def test_large_arrays_number_points_across_the_whole_array(threads):
    # eval works through large arrays in pieces: $id must still be the index in the whole
    # array, every point must be evaluated, and a NaN far in must still be found.
    n = 300_001
    P = np.zeros((n, 3))
    P[:, 0] = np.arange(n) * 0.5
    e = gale.compile(source="[$id, $P[0] * 2, 1]")
    got = e.eval(P, precision="double", threads=threads)
    np.testing.assert_array_equal(got[:, 0], np.arange(n))
    np.testing.assert_array_equal(got[:, 1], np.arange(n, dtype=np.float64))
    P[n - 2, 2] = np.nan
    with pytest.raises(gale.ArgumentError, match=f"P\\[{n - 2}\\] is not finite"):
        e.eval(P, threads=threads)


def test_out_writes_in_place_and_is_checked():
    e = gale.compile(source="$P * 3")
    P = np.random.default_rng(5).uniform(-1, 1, (1000, 3))
    out = np.full((1000, 3), np.nan, dtype=np.float32)
    got = e.eval(P, out=out)
    assert got is out or np.shares_memory(got, out)
    np.testing.assert_array_equal(out, e.eval(P))
    for bad in [np.empty((1000, 3)), np.empty((999, 3), np.float32), np.empty((3, 1000), np.float32).T, [0.0]]:
        with pytest.raises(gale.ArgumentError, match="out must be"):
            e.eval(P, out=bad)
