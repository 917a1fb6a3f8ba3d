# gale.Scene: sample equals `gale sample` on the same grid, and simulate gives the frames of
# `gale sim` (positions against its OBJ files, stats against run.json), with `set` overrides.
import json

import numpy as np

import gale
from conftest import run_gale


def read_obj_vertices(path):
    with open(path) as f:
        return np.array([[float(v) for v in line.split()[1:4]] for line in f if line.startswith("v ")])


def test_sample_equals_gale_sample(src, tmp_path, gale_bin):
    scene = src / "examples" / "02_gusts" / "scene.toml"
    run_gale(gale_bin, "sample", scene, "--bounds", "-2,0,-1,2,2,1", "--res", "12", "--time", "1.25",
             "-o", tmp_path / "g.npy")
    want = np.load(tmp_path / "g.npy")
    got = gale.Scene(str(scene)).sample(bounds=(-2, 0, -1, 2, 2, 1), res=12, t=1.25)
    assert got.dtype == np.float32
    assert got.shape == (12, 6, 6, 3)  # voxel 4/12 m: 2 m and 2 m need 6 cells
    np.testing.assert_array_equal(got.reshape(want.shape), want)
    exact = gale.Scene(str(scene)).sample(bounds=(-2, 0, -1, 2, 2, 1), res=(4, 5, 6), t=1.25)
    assert exact.shape == (4, 5, 6, 3)


def test_simulate_equals_gale_sim(src, tmp_path, gale_bin):
    scene = src / "examples" / "03_cape" / "scene.toml"
    out = tmp_path / "sim"
    run_gale(gale_bin, "sim", scene, "-o", out, "--frames", "1:10", "--set", "cloth.cape.drag=0.9",
             "--set", "cloth.cape.lift=0.7")
    run = json.loads((out / "run.json").read_text())
    s = gale.Scene(str(scene), set={"cloth.cape.drag": 0.9, "cloth.cape.lift": 0.7})
    sim = s.simulate(frames=(1, 10))
    assert sim.settings["objects"][0]["drag"] == 0.9
    frames = list(sim)
    assert [f.frame for f in frames] == list(range(1, 11))
    assert len(run["frames"]) == 10
    for f, want in zip(frames, run["frames"]):
        assert f.time == want["time"]
        got = dict(f.stats)
        got.pop("wall_seconds")
        want = dict(want)
        want.pop("wall_seconds")
        assert got == want
        x = f.positions["cape"]
        assert x.shape == (768, 3) and x.dtype == np.float64
        obj = read_obj_vertices(out / f"cape.{f.frame:04d}.obj")
        # The OBJ holds 9 significant digits of the same doubles.
        np.testing.assert_allclose(x, obj, rtol=1e-8, atol=1e-9)
    # The cloth moved: the comparison is not of two initial states.
    assert np.abs(frames[-1].positions["cape"] - frames[0].positions["cape"]).max() > 1e-3
    # Iteration ends after the last frame.
    assert next(iter(sim), None) is None


def test_warnings_as_in_run_json(src, tmp_path, gale_bin):
    # Lift above drag is a likely mistake: gale sim warns and writes it to run.json's warnings,
    # and the Python simulation has the same list; the scene as shipped has none.
    scene = src / "examples" / "03_cape" / "scene.toml"
    out = tmp_path / "sim"
    run_gale(gale_bin, "sim", scene, "-o", out, "--frames", "1:2", "--set", "cloth.cape.lift=1.5")
    run = json.loads((out / "run.json").read_text())
    sim = gale.Scene(str(scene), set={"cloth.cape.lift": 1.5}).simulate(frames=(1, 2))
    assert len(run["warnings"]) == 1 and "exceeds drag" in run["warnings"][0]
    assert run["warnings"][0].startswith(str(scene) + ":")
    assert sim.warnings == run["warnings"]
    assert gale.Scene(str(scene)).simulate(frames=(1, 2)).warnings == []


def test_a_late_range_starts_from_the_simulated_state(src):
    # Frames 6..9 on their own are the frames 6..9 of the run from the scene's first frame: the
    # frames before the range are simulated first (never the rest mesh at frame 6).
    s = gale.Scene(str(src / "examples" / "03_cape" / "scene.toml"))
    full = {f.frame: f.positions["cape"] for f in s.simulate(frames=(1, 9))}
    late = list(s.simulate(frames=(6, 9)))
    assert [f.frame for f in late] == [6, 7, 8, 9]
    for f in late:
        np.testing.assert_array_equal(f.positions["cape"], full[f.frame])
    assert np.abs(full[6] - full[1]).max() > 1e-3  # frame 6 is not the rest shape
