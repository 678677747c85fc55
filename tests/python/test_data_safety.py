"""A user's data is never lost: atomic writes, inputs never overwritten, every
failed write an error naming the file, readers that name the file on junk, and
the bad calls of the attack report (issue #30) refused by name."""

import errno
import os
from pathlib import Path

import boxplus as bp
import numpy as np
import pytest
from boxplus import files
from boxplus.calib import io

# ---- atomic writes ------------------------------------------------------------------------


def test_a_failed_write_keeps_the_previous_file_and_leaves_no_temporary(tmp_path, monkeypatch):
    target = tmp_path / "result.yml"
    files.write_atomically(target, "old content\n")
    real_fsync = os.fsync

    def full_disk(fd):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(os, "fsync", full_disk)
    with pytest.raises(OSError, match="result.yml"):
        files.write_atomically(target, "new content that does not fit\n")
    monkeypatch.setattr(os, "fsync", real_fsync)
    assert target.read_text() == "old content\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["result.yml"]


def test_an_exception_while_producing_the_content_keeps_the_previous_file(tmp_path):
    target = tmp_path / "plot.png"
    target.write_bytes(b"previous")
    with pytest.raises(RuntimeError), files.atomic_path(target) as tmp:
        tmp.write_bytes(b"half")
        raise RuntimeError("the plot failed")
    assert target.read_bytes() == b"previous"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["plot.png"]


def test_writing_to_a_full_device_is_an_error_not_a_silent_loss():
    if not Path("/dev/full").exists():
        pytest.skip("no /dev/full")
    with pytest.raises(OSError, match="/dev/full"):
        files.write_atomically("/dev/full", "x" * 100)
    assert Path("/dev/full").is_char_device()  # written to, never replaced


def test_a_new_file_gets_the_umask_mode_and_a_replaced_one_keeps_its_mode(tmp_path):
    new = tmp_path / "new.txt"
    files.write_atomically(new, "a")
    umask = os.umask(0)
    os.umask(umask)
    assert new.stat().st_mode & 0o777 == 0o666 & ~umask
    new.chmod(0o600)
    files.write_atomically(new, "b")
    assert new.stat().st_mode & 0o777 == 0o600 and new.read_text() == "b"


def test_refuse_overwriting_sees_links(tmp_path):
    src = tmp_path / "in.g2o"
    src.write_text("x")
    link = tmp_path / "link.g2o"
    link.symlink_to(src)
    with pytest.raises(ValueError, match="is the input"):
        files.refuse_overwriting(link, [src], "tool")
    files.refuse_overwriting(tmp_path / "other.g2o", [src], "tool")


# ---- calibration files --------------------------------------------------------------------


@pytest.mark.parametrize("reader", [io.read_opencv_yaml, io.read_camera_info, io.read_camchain])
@pytest.mark.parametrize("junk", [bytes(range(256)) * 4, b"\x00" * 64, b"camera_names: [a]\x00\xff"])
def test_yaml_readers_name_the_file_on_binary_junk(tmp_path, reader, junk):
    pytest.importorskip("yaml")
    path = tmp_path / "junk.yml"
    path.write_bytes(junk)
    with pytest.raises(ValueError, match="junk.yml"):
        reader(path)


def test_calibration_writers_are_atomic(tmp_path, monkeypatch):
    cam = io.CalibratedCamera("left", "pinhole", [500.0, 500.0, 320.0, 240.0], (640, 480))
    path = tmp_path / "calibration.yml"
    io.write_opencv_yaml(path, [cam])
    before = path.read_bytes()

    def fail(*a, **k):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(os, "fsync", fail)
    with pytest.raises(OSError, match="calibration.yml"):
        io.write_opencv_yaml(path, [io.CalibratedCamera("left", "pinhole", [1.0, 1.0, 1.0, 1.0], (640, 480))])
    assert path.read_bytes() == before


# ---- bad calls refused by name (the attack report's probes) -------------------------------


def test_composing_poses_of_different_kinds_is_refused():
    with pytest.raises(TypeError, match="SE3 \\* p: expected points .* got a SE2"):
        bp.SE3() * bp.SE2()
    with pytest.raises(TypeError, match="got a SO3"):
        bp.SE2() * bp.SO3()
    assert np.allclose(bp.SE3(t=[1.0, 2.0, 3.0]) * np.zeros(3), [1.0, 2.0, 3.0])


def test_rn_of_a_numpy_integer_is_its_dimension():
    assert len(bp.Rn(np.int64(3))) == 3 and np.array_equal(bp.Rn(np.int64(3)).vec, np.zeros(3))
    assert np.array_equal(bp.Rn(np.array([3.0])).vec, [3.0])
    with pytest.raises(TypeError, match="bool"):
        bp.Rn(True)


def test_huge_finite_quaternions_normalise_like_the_g2o_reader():
    assert np.allclose(bp.SO3([1e308] * 4).quat, [0.5] * 4)
    assert np.allclose(bp.S2([1e308, 0.0, 0.0]).vec, [1.0, 0.0, 0.0])
    with pytest.raises(ValueError, match="finite and non-zero"):
        bp.SO3([np.inf, 0.0, 0.0, 1.0])


def test_compound_members_may_not_shadow_the_compound_interface():
    for name in ["boxplus", "boxminus", "dof", "idx_of", "to_ambient"]:
        with pytest.raises(ValueError, match=f"member name '{name}' is taken"):
            bp.make_compound("c", **{name: bp.Rn(1)})


class _NoDof(bp.ManifoldValue):
    dof = 0

    def __init__(self, a=(0.0,)):
        self.a = np.asarray(a, float)

    def boxplus(self, d):
        return self

    def boxminus(self, other):
        return np.zeros(0)

    def to_ambient(self):
        return self.a

    @classmethod
    def from_ambient(cls, a):
        return cls(a)


class _HalfDof(_NoDof):
    dof = 2.5


@pytest.mark.parametrize("cls", [_NoDof, _HalfDof])
def test_a_user_manifold_with_a_bad_dof_is_named(cls):
    with pytest.raises(TypeError, match=f"{cls.__name__}.dof must be an int"):
        bp.OptimizationProblem().add_random_var(cls())


def test_constants_must_be_a_sequence():
    o = bp.OptimizationProblem()
    x = o.add_random_var(bp.Rn([1.0]))
    with pytest.raises(TypeError, match="constants must be a tuple or list"):
        o.add_measurement([0.0], lambda v, c: v.vec, [x], constants=5)
    with pytest.raises(TypeError, match="constants must be a tuple or list"):
        o.add_measurements(np.zeros((1, 1)), lambda v, c: v.vec, [[x]], constants="abc")


def test_variable_names_are_strings_and_unique():
    o = bp.OptimizationProblem()
    with pytest.raises(TypeError, match="name must be a str"):
        o.add_random_var(bp.Rn([1.0]), name=5)
    o.add_random_var(bp.Rn([1.0]), name="a")
    with pytest.raises(ValueError, match="variable 'a': a variable of this name exists"):
        o.add_random_var(bp.Rn([2.0]), name="a")
    assert o.num_variables == 1


# ---- boxplus-calib never writes over what it reads ----------------------------------------


def _render_chessboard_views(folder: Path, n: int = 6) -> None:
    """Pinhole images of a 9×6-corner chessboard (25 mm) from n poses, as PNGs."""
    cv2 = pytest.importorskip("cv2")
    S, margin = 40, 40  # board image: pixels per square, white border
    rows, cols = 7, 10  # squares
    board = np.full((rows * S + 2 * margin, cols * S + 2 * margin), 255, np.uint8)
    for r in range(rows):
        for c in range(cols):
            if (r + c) % 2 == 0:
                board[margin + r * S:margin + (r + 1) * S, margin + c * S:margin + (c + 1) * S] = 0
    # board-image pixel → board metres (origin at the first inner corner)
    sq = 0.025
    A = np.array([[sq / S, 0, -(margin + S) * sq / S], [0, sq / S, -(margin + S) * sq / S], [0, 0, 1]])
    K = np.array([[520.0, 0, 320.0], [0, 520.0, 240.0], [0, 0, 1]])
    rng = np.random.default_rng(3)
    for i in range(n):
        R = bp.SO3.exp(rng.normal(0, 0.25, 3) + [np.pi, 0, 0]).R
        t = np.array([-0.1, 0.06, 0.0]) + R @ [0.0, 0.0, 0.0]
        t = -R @ [0.1, 0.06, 0.0] + [rng.normal(0, 0.02), rng.normal(0, 0.02), 0.45 + 0.05 * i]
        H = K @ np.column_stack([R[:, 0], R[:, 1], t]) @ A
        img = cv2.warpPerspective(board, H, (640, 480), borderValue=255)
        cv2.imwrite(str(folder / f"view{i:02d}.png"), img)


def test_calib_cli_refuses_its_input_folder_and_skips_its_own_outputs(tmp_path, capsys):
    pytest.importorskip("cv2")
    pytest.importorskip("matplotlib")
    from boxplus.calib.cli import main

    images = tmp_path / "cam"
    images.mkdir()
    _render_chessboard_views(images)
    args = ["--target", "chessboard:9x6:0.025", "--model", "pinhole", "--quiet"]
    with pytest.raises(SystemExit, match="is the folder camera 'cam' reads its images from"):
        main([*args, "--out", str(images), str(images)])
    assert sorted(p.name for p in images.iterdir()) == [f"view{i:02d}.png" for i in range(6)]
    (tmp_path / "afile").write_text("x")
    with pytest.raises(SystemExit, match="is a file, not a folder"):
        main([*args, "--out", str(tmp_path / "afile"), str(images)])
    assert main([*args, "--write-into-input", "--out", str(images), str(images)]) == 0
    first = capsys.readouterr().out
    assert "6 views" in first and (images / "rig.png").exists()
    # a second run reads the same folder: the plots written there are not images of the board
    assert main([*args, "--write-into-input", "--out", str(images), str(images)]) == 0
    assert "6 views" in capsys.readouterr().out


def test_calib_cli_names_a_glob_camera_after_the_glob(tmp_path, capsys):
    pytest.importorskip("cv2")
    from boxplus.calib.cli import main

    images = tmp_path / "imgs"
    images.mkdir()
    _render_chessboard_views(images)
    out = tmp_path / "out"
    assert main(["--target", "chessboard:9x6:0.025", "--model", "pinhole", "--quiet", "--no-plots",
                 "--out", str(out), f"{images}/view*.png"]) == 0
    assert "view:" in capsys.readouterr().out
    assert [c.name for c in io.read_opencv_yaml(out / "calibration.yml")] == ["view"]
