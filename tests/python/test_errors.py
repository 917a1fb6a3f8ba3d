# Errors are exceptions, never crashes: compile errors carry `gale check`'s text and the list of
# diagnostics; bad shapes, dtypes, NaN points, unknown parameters and bad `set` paths raise.
import numpy as np
import pytest

import gale
from conftest import run_gale

BAD = "$a = 1;\nfoo = $P + ;\nbar($a)\n"


def test_compile_error_text_is_gale_check(tmp_path, gale_bin):
    (tmp_path / "bad.se").write_text(BAD)
    r = run_gale(gale_bin, "check", tmp_path / "bad.se", check=False)
    assert r.returncode == 1
    with pytest.raises(gale.CompileError) as info:
        gale.compile(str(tmp_path / "bad.se"))
    assert str(info.value) == r.stderr
    diags = info.value.diagnostics
    assert diags and diags[0]["severity"] == "error" and diags[0]["line"] == 2
    assert isinstance(info.value, gale.Error)
    r = run_gale(gale_bin, "check", "-e", "1 +", check=False)
    with pytest.raises(gale.CompileError) as info:
        gale.compile(source="1 +")
    assert str(info.value) == r.stderr


def test_missing_file_and_argument_mixups(tmp_path):
    with pytest.raises(gale.Error) as info:
        gale.compile(str(tmp_path / "none.se"))
    assert "none.se" in str(info.value) and isinstance(info.value, OSError)
    with pytest.raises(gale.ArgumentError):
        gale.compile()
    with pytest.raises(gale.ArgumentError):
        gale.compile("a.se", source="1")


@pytest.mark.parametrize("P,what", [
    (np.zeros((4, 2)), "shape"),
    (np.zeros(3), "shape"),
    (np.zeros((4, 3), dtype=np.int64), "float32 or float64"),
    (np.array([[0.0, np.nan, 0.0]]), "not finite"),
    (np.array([[0.0, 0.0, np.inf]], dtype=np.float32), "not finite"),
    ([[0.0, 0.0, 0.0]], "numpy array"),
])
def test_bad_points_raise(P, what):
    e = gale.compile(source="$P")
    with pytest.raises(gale.ArgumentError, match=what):
        e.eval(P)


def test_bad_parameters_and_options_raise():
    e = gale.compile(source="$speed = 5; # 0, 40\n$speed * $P")
    P = np.zeros((2, 3))
    with pytest.raises(gale.ArgumentError, match="unknown parameter 'sped'.*declared: speed"):
        e.eval(P, params={"sped": 1})
    with pytest.raises(gale.ArgumentError, match="component"):
        e.eval(P, params={"speed": [1, 2]})
    with pytest.raises(ValueError):  # ArgumentError is a ValueError too
        e.eval(P, params={"speed": "fast"})
    with pytest.raises(gale.ArgumentError, match="precision"):
        e.eval(P, precision="half")
    with pytest.raises(gale.ArgumentError, match="threads"):
        e.eval(P, threads=-1)
    with pytest.raises(gale.ArgumentError, match="finite"):
        e.eval(P, t=float("nan"))


def test_scene_errors_raise(src, tmp_path):
    scene = str(src / "examples" / "03_cape" / "scene.toml")
    with pytest.raises(gale.SceneError, match="did you mean 'drag'"):
        gale.Scene(scene, set={"cloth.cape.dragg": 0.8})
    with pytest.raises(gale.SceneError):
        gale.Scene(scene, set={"nosuch.key": 1})
    with pytest.raises(gale.ArgumentError):
        gale.Scene(scene, set={"cloth.cape.drag": object()})
    with pytest.raises(OSError):
        gale.Scene(str(tmp_path / "none.toml"))
    s = gale.Scene(scene)
    for kwargs in [dict(bounds=(0, 0, 0, 1, 1)), dict(bounds=(0, 0, 0, 0, 1, 1)), dict(bounds=(0, 0, 0, 1, 1, 1), res=0),
                   dict(bounds=(0, 0, 0, 1, 1, 1), res=(2, 2)), dict(bounds=(0, 0, 0, float("nan"), 1, 1))]:
        with pytest.raises(gale.ArgumentError):
            s.sample(**kwargs)
    with pytest.raises(gale.ArgumentError):
        s.simulate(frames=(5, 2))
    with pytest.raises(gale.ArgumentError):
        s.simulate(frames="1:4")
