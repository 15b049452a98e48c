"""Saved results read back (rf.load_npz, base.persistence.read_result) and the paths of the exports: what is not
a path (None, 3) is a ValueError naming ``path`` in every one of them (it was TypeError from pathlib or numpy),
a file that is not a saved Result one too, with the cause (it was KeyError or numpy's advice to unpickle it),
while a missing file stays a FileNotFoundError."""

import os
import zipfile

import matplotlib.pyplot as plt
import numpy as np
import pytest

import rigidfem as rf
from rigidfem import animation

NOT_A_PATH = r"^path: expected a file path \(str or os\.PathLike\), got "


@pytest.fixture(scope="module")
def run():
    model, _ = rf.samples.pendulum()
    system = model.compile()
    return model, system, rf.simulate(system, 0.05, method="rk4", dt=0.01, q0=[0.3])


@pytest.mark.parametrize("wrong, said", [(None, "None"), (3, "3"), (b"run.npz", "b'run.npz'"), ("", "''")])
def test_what_is_not_a_path_is_named_by_every_export_and_load_npz(run, wrong, said, tmp_path):
    _, system, result = run
    viewer = rf.view(system, result)
    anim = rf.animate(result, frames=2)
    anim._draw_was_started = True  # never rendered on purpose (no "deleted without rendering" warning)
    for call in (lambda: result.to_npz(wrong), lambda: result.to_csv(wrong), lambda: rf.load_npz(wrong),
                 lambda: rf.load_npz(wrong, system), lambda: viewer.to_html(wrong), lambda: animation.save(anim, wrong)):
        with pytest.raises(ValueError, match=NOT_A_PATH + said.replace("(", r"\(")):
            call()
    assert not os.listdir(tmp_path)
    plt.close("all")


def test_paths_as_str_and_pathlike_still_work(run, tmp_path):
    _, system, result = run
    for path in (tmp_path / "a.npz", str(tmp_path / "b.npz")):
        back = rf.load_npz(result.to_npz(path), system)
        assert np.array_equal(back.q, result.q) and np.array_equal(back.t, result.t)
    assert rf.view(system, result).to_html(str(tmp_path / "v.html")).stat().st_size > 0
    assert result.to_csv(tmp_path / "r.csv") == tmp_path / "r.csv"


def test_the_system_is_checked_before_the_path(run):
    model, _, _ = run
    with pytest.raises(ValueError, match=r"^system: expected a compiled System"):
        rf.load_npz(None, model)


def _archive(path, **arrays):
    fields = {"t": np.arange(3.0), "q": np.zeros((3, 1)), "qd": np.zeros((3, 1)), "coordinate_names": np.array(["a"]),
              "method": np.array("rk4"), "stats": np.array("{}"), "interrupted": np.array(False)}
    fields.update(arrays)
    np.savez(path, **{k: v for k, v in fields.items() if v is not None})
    return path


def _written(path, data: bytes, suffix=""):
    with open(path, "wb") as f:
        f.write(data)
    return path + suffix


def _truncated(path):
    np.savez(path, a=np.arange(30.0))
    with open(path, "rb") as f:
        data = f.read()
    return _written(path, data[: len(data) // 2])


def _zip_of_junk(path):
    with zipfile.ZipFile(path, "w") as z:
        z.writestr("t.npy", "not an array")
    return path


@pytest.mark.parametrize("make, cause", [
    (lambda p: _written(p, b"not an archive"), r"not a NumPy \.npz archive: it begins with b'not '"),
    (lambda p: _written(p, b""), r"not a NumPy \.npz archive: it begins with b''"),
    (lambda p: np.save(p, np.arange(3.0)) or p + ".npy", r"not a NumPy \.npz archive: it begins with b'\\x93NUM'"),
    (lambda p: np.savez(p, a=np.arange(3.0)) or p, r"an archive without the arrays of a Result: coordinate_names is "
                                                   r"not a file in the archive"),
    (lambda p: _archive(p, qd=None), r"an archive without the arrays of a Result: qd is not a file"),
    (lambda p: _archive(p, coordinate_names=np.array([None], dtype=object)), r"ValueError: Object arrays cannot be "
                                                                             r"loaded when allow_pickle=False"),
    (lambda p: _archive(p, stats=np.array("{")), r"JSONDecodeError: "),
    (lambda p: _archive(p, q=np.zeros((3, 2))), r"its q has shape \(3, 2\), expected \(len\(t\), "
                                                r"len\(coordinate_names\)\) = \(3, 1\)"),
    (lambda p: _archive(p, t=np.array(["0", "1", "2"])), r"its t holds <U1, not numbers"),
    (lambda p: _archive(p, t=np.zeros((3, 1))), r"its t has shape \(3, 1\), expected one dimension"),
    (_truncated, r"BadZipFile: "),
    (_zip_of_junk, r"an archive without the arrays of a Result"),
])
def test_a_file_that_is_not_a_saved_result_is_named_with_its_cause(make, cause, tmp_path, run):
    """KeyError 'coordinate_names is not a file in the archive', or numpy's 'This file contains pickled (object)
    data. If you trust the file you can load it unsafely ...' for a text file."""
    _, system, _ = run
    path = make(str(tmp_path / "foreign.npz"))
    for args in ((path,), (path, None), (path, system)):
        with pytest.raises(ValueError, match=rf"^path: expected a file written by Result\.to_npz, got '{path}' "
                                             rf"\({cause}"):
            rf.load_npz(*args)


def test_a_missing_file_stays_a_file_not_found_error(tmp_path, run):
    _, system, _ = run
    with pytest.raises(FileNotFoundError):
        rf.load_npz(tmp_path / "none.npz", system)
    with pytest.raises(IsADirectoryError):
        rf.load_npz(tmp_path)


def test_another_systems_coordinates_are_still_named_system(run, tmp_path):
    _, _, result = run
    other = rf.samples.double_pendulum()[0].compile()
    with pytest.raises(ValueError, match=r"^system: expected a System with the coordinates"):
        rf.load_npz(result.to_npz(tmp_path / "run.npz"), other)
