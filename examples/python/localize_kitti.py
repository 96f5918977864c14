#!/usr/bin/env python3
"""Localize a KITTI-layout stereo sequence in a plane map and plot it against the ground truth.

  examples/python/localize_kitti.py SEQUENCE_DIR POSES.txt PLANES.json [OUT.png]

Without data: python3 -c "import planeloc; print(planeloc.sim.generate('/tmp/sim'))" gives a
sequence, its poses and its GT planes. Needs the module on PYTHONPATH (build/python) or installed.
"""
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

import planeloc

sequence_dir, poses_path, planes_path = sys.argv[1:4]
out = sys.argv[4] if len(sys.argv) > 4 else "localize_kitti.png"
sequence = planeloc.KittiSequence(sequence_dir)
gt = planeloc.read_poses(poses_path)
localizer = planeloc.Localizer(sequence.camera, planeloc.read_plane_map(planes_path),
                               initial_pose=gt[0], init_sigma=(2.0, 0.5, 5.0))
poses = []
for i in range(len(sequence)):
    left, right = sequence.stereo_pair(i)
    frame = localizer.track(left, right, sequence.timestamp(i))
    poses.append(frame["pose"])
localizer.finish()
poses = np.array(poses)
ate = planeloc.eval.ate(gt[:len(poses)], poses, align="none")
print(f"{len(poses)} frames, map lock {frame['map_lock']}, ATE RMSE {ate['rmse']:.3f} m")
plt.plot(gt[:, 0, 3], gt[:, 2, 3], "k--", label="ground truth")
plt.plot(poses[:, 0, 3], poses[:, 2, 3], label=f"planeloc (ATE {ate['rmse']:.3f} m)")
plt.axis("equal"), plt.xlabel("x (m)"), plt.ylabel("z (m)"), plt.legend()
plt.savefig(out, dpi=120)
