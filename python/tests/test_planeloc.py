"""The Python module against the CLI (issue 36 item 2): the same poses bit for bit, the same ATE,
errors as ValueError with the CLI's message. Needs PLANELOC_BIN (the planeloc CLI) and the
module on PYTHONPATH (ctest sets both: test python.module)."""
import json
import os
import subprocess

import numpy as np
import pytest

import planeloc

BIN = os.environ.get("PLANELOC_BIN", "planeloc")


@pytest.fixture(scope="module")
def tiny(tmp_path_factory):
    """A 20-frame tiny drive, its GT planes and the CLI's deterministic run on them."""
    work = tmp_path_factory.mktemp("tiny")
    drive = planeloc.sim.generate(work / "sim", preset="tiny", seed=3, frames=20)
    traj = work / "cli.txt"
    subprocess.run([BIN, "run", "--sequence", str(drive["sequence"]), "--init-pose-from",
                    str(drive["poses"]), "--planes", str(drive["planes"]), "--init-sigma",
                    "0 0 0", "--deterministic", "--out", str(traj)],
                   check=True, capture_output=True)
    return {"work": work, "drive": drive, "cli": traj}


def localize(drive, **kwargs):
    sequence = planeloc.KittiSequence(drive["sequence"])
    gt = planeloc.read_poses(drive["poses"])
    localizer = planeloc.Localizer(sequence.camera, planeloc.read_plane_map(drive["planes"]),
                                   initial_pose=gt[0], init_sigma=(0, 0, 0), **kwargs)
    poses = []
    for i in range(len(sequence)):
        left, right = sequence.stereo_pair(i)
        poses.append(localizer.track(left, right, sequence.timestamp(i))["pose"])
    localizer.finish()
    return np.array(poses)


def test_poses_equal_the_cli_bit_for_bit(tiny):
    poses = localize(tiny["drive"], deterministic=True)
    cli = planeloc.read_poses(tiny["cli"])
    assert poses.shape == (20, 4, 4)
    # `planeloc run` writes each number in its shortest round-trip form: equal means equal.
    assert np.array_equal(poses[:, :3, :], cli[:, :3, :])


def test_ate_equals_the_cli(tiny):
    gt = planeloc.read_poses(tiny["drive"]["poses"])
    est = planeloc.read_poses(tiny["cli"])
    out = tiny["work"] / "ate.json"
    subprocess.run([BIN, "eval", "--gt", str(tiny["drive"]["poses"]), "--est", str(tiny["cli"]),
                    "--align", "se3", "--json", str(out)], check=True, capture_output=True)
    cli = json.loads(out.read_text())
    ours = planeloc.eval.ate(gt, est, align="se3")
    stats = cli["ape"] if "ape" in cli else cli
    for key in ("rmse", "mean", "median", "std", "min", "max"):
        assert ours[key] == pytest.approx(find(stats, key), rel=1e-12, abs=1e-15), key
    # The same poses as (N, 12) KITTI rows give the same numbers.
    rows = est[:, :3, :].reshape(len(est), 12)
    assert planeloc.eval.ate(gt, rows, align="se3")["rmse"] == ours["rmse"]


def find(document, key):
    """The first value under `key` anywhere in a nested JSON document."""
    if isinstance(document, dict):
        if key in document and not isinstance(document[key], (dict, list)):
            return document[key]
        for value in document.values():
            found = find(value, key)
            if found is not None:
                return found
    return None


def test_a_bad_plane_map_raises_value_error_naming_the_file(tmp_path):
    bad = tmp_path / "broken.json"
    bad.write_text('{"planes": [{"id": 0, "normal": [0, 0')
    with pytest.raises(ValueError, match="broken.json:1"):
        planeloc.read_plane_map(bad)


def test_arrays_of_the_wrong_shape_or_type_are_value_errors(tiny):
    sequence = planeloc.KittiSequence(tiny["drive"]["sequence"])
    localizer = planeloc.Localizer(sequence.camera)
    left, right = sequence.stereo_pair(0)
    with pytest.raises(ValueError, match="left"):
        localizer.track(left.astype(np.float32), right, 0.0)
    with pytest.raises(ValueError, match="right"):
        localizer.track(left, right[:, :, None].repeat(2, axis=2), 0.0)
    with pytest.raises(ValueError, match="initial_pose"):
        planeloc.Localizer(sequence.camera, initial_pose=np.zeros((2, 2)))
    with pytest.raises(ValueError, match="gt"):
        planeloc.eval.ate(np.zeros((3, 5)), np.zeros((3, 12)))
    with pytest.raises(ValueError, match="align"):
        gt = planeloc.read_poses(tiny["drive"]["poses"])
        planeloc.eval.ate(gt, gt, align="affine")


def test_the_plane_map_as_arrays(tiny):
    plane_map = planeloc.read_plane_map(tiny["drive"]["planes"])
    assert len(plane_map) == len(plane_map.planes) > 0
    assert plane_map.normals.shape == (len(plane_map), 3)
    assert np.allclose(np.linalg.norm(plane_map.normals, axis=1), 1.0)
    first = plane_map.planes[0]
    assert first["polygon"].shape[1] == 3
    # Each outline lies on its plane.
    assert np.allclose(first["polygon"] @ first["normal"] + first["d"], 0.0, atol=1e-6)


def test_the_example_localizes_and_plots(tiny):
    example = os.path.join(os.path.dirname(__file__), "..", "..", "examples", "python",
                           "localize_kitti.py")
    out = tiny["work"] / "example.png"
    drive = tiny["drive"]
    result = subprocess.run(["python3" if not os.path.exists("/usr/bin/python3")
                             else "/usr/bin/python3", example, str(drive["sequence"]),
                             str(drive["poses"]), str(drive["planes"]), str(out)],
                            capture_output=True, text=True, env=os.environ)
    assert result.returncode == 0, result.stderr
    assert "20 frames" in result.stdout
    assert out.stat().st_size > 10000
