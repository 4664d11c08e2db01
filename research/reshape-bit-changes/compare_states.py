"""The largest relative difference, per particle field, between the final checkpoints of two runs of one scenario.

Usage: python3 compare_states.py RUN_DIR_A RUN_DIR_B
Reads the newest ckpt-*.h5 of each directory with h5py (the particle datasets are the same in checkpoint formats 4
and 5) and prints, for each field, max |a - b| / max |a| over all particles and components, and the step.
"""
import glob
import sys

import h5py
import numpy as np

FIELDS = ["position_m", "velocity_m_per_s", "angular_velocity_rad_per_s", "force_n", "torque_n_m", "liquid_m3"]


def newest(run_dir):
    return sorted(glob.glob(f"{run_dir}/ckpt-*.h5"))[-1]


def main(a_dir, b_dir):
    a, b = h5py.File(newest(a_dir), "r"), h5py.File(newest(b_dir), "r")
    assert a.attrs["step"] == b.attrs["step"], "the runs stopped at different steps"
    print(f"step {a.attrs['step']}")
    for field in FIELDS:
        x, y = np.asarray(a["particles"][field]), np.asarray(b["particles"][field])
        scale = np.max(np.abs(x))
        rel = np.max(np.abs(x - y)) / scale if scale > 0 else 0.0
        identical = np.array_equal(x.view(np.uint64), y.view(np.uint64))
        print(f"  {field:28s} max relative difference {rel:.3e}{'  (identical bits)' if identical else ''}")


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
