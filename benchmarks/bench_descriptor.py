"""Speed of the per-frame features and of the synthetic stream generator (issues 2, 10).

``PoseDescriptor.transform`` on one core, with the compiled kernel (numba,
when installed) and with the numpy implementation, as frames per second of
wall time and of process CPU time (the better figure on a shared machine: wall
time there includes the time other jobs hold the core). Median of 5 calls
after one warm-up (which also compiles the kernel, or loads it from numba's
cache). ``JointFeatures.transform`` too, with the statistics of the whole
sequence and with running ones (every row as the live step makes it).
Issue 10's target: >= 1,000,000 frames/s for the 183-D descriptor.
"""

import statistics
import time

import numpy as np
from _common import one_core

import skgesture._descriptor._compute as descriptor_module
from skgesture import JointFeatures, PoseDescriptor
from skgesture._stream import stream_frames
from skgesture.datasets import make_gesture_streams

SHORT_FRAMES = 60  # length of the short sequences of the per-sequence overhead row
TARGET_FPS = 1_000_000  # issue 10, 183-D descriptor on one core
LIVE_FRAMES = 2_000  # frames pushed one at a time in the live-step row


def _median(func, repeat=5, warmup=1):
    for _ in range(warmup):
        func()
    wall, cpu = [], []
    for _ in range(repeat):
        w0, c0 = time.perf_counter(), time.process_time()
        func()
        wall.append(time.perf_counter() - w0)
        cpu.append(time.process_time() - c0)
    return statistics.median(wall), statistics.median(cpu)


def _row(what, path, n_frames, wall, cpu):
    return {
        "what": what,
        "path": path,
        "frames": n_frames,
        "median s": wall,
        "frames/s": n_frames / wall,
        "frames/s (CPU)": n_frames / cpu,
        "µs/frame (CPU)": 1e6 * cpu / n_frames,
    }


def _push_each(desc, frames):
    """Stream ``frames`` through the descriptor's live step, one per push."""
    state = desc.stream_init()
    for t in range(len(frames)):
        _, state = desc.stream_step(state, stream_frames(frames[t : t + 1], t))
    desc.stream_flush(state)


def _paths():
    """``(name, use_compiled)`` of the implementations available here."""
    out = [("numpy", False)]
    if descriptor_module._compiled_kernel() is not None:  # numba, not disabled
        out.insert(0, ("compiled", True))
    return out


def run(quick=False):
    """Rows: descriptor frames/s on one core per joint set and path; generator."""
    n_seq = 20 if quick else 100
    data = make_gesture_streams(n_seq, random_state=0)
    n_frames = sum(len(x) for x in data.X)
    rows = []
    before = descriptor_module.USE_COMPILED
    try:
        with one_core():
            for path, compiled in _paths():
                descriptor_module.USE_COMPILED = compiled
                for joints in ("paper11", "full20"):
                    desc = PoseDescriptor(joints=joints).fit(data.X)
                    wall, cpu = _median(lambda: desc.transform(data.X))
                    what = f"PoseDescriptor ({joints}, {desc.n_features_out_}-D)"
                    rows.append(_row(what, path, n_frames, wall, cpu))
                    # The computation alone: no input checks, no masks.
                    spec = desc._spec()
                    wall, cpu = _median(
                        lambda: desc._describe_all(data.X, spec, standardize=True)
                    )
                    what = f"  descriptor computation only ({joints})"
                    rows.append(_row(what, path, n_frames, wall, cpu))
                # The same frames as many short sequences: per-sequence overhead.
                short = [
                    x[i : i + SHORT_FRAMES]
                    for x in data.X
                    for i in range(0, len(x) - SHORT_FRAMES + 1, SHORT_FRAMES)
                ]
                n_short = sum(len(x) for x in short)
                desc = PoseDescriptor().fit(data.X)
                wall, cpu = _median(lambda: desc.transform(short))
                what = f"PoseDescriptor (paper11, {SHORT_FRAMES}-frame sequences)"
                rows.append(_row(what, path, n_short, wall, cpu))
                # The live step, one frame per push (the recogniser's push()).
                live = np.concatenate(data.X)[: LIVE_FRAMES // (4 if quick else 1)]
                hold = PoseDescriptor(fill="hold").fit(data.X)
                wall, cpu = _median(lambda: _push_each(hold, live), repeat=3)
                what = "  live step, one frame per push (paper11)"
                rows.append(_row(what, path, len(live), wall, cpu))
            # The recommended model's other features; "running": offline as
            # live, every row with the statistics of its own trailing window.
            for joints in ("paper11", "full20"):
                for stats in ("sequence", "running"):
                    feats = JointFeatures(joints=joints, fill="hold", statistics=stats)
                    feats.fit(data.X)
                    wall, cpu = _median(lambda: feats.transform(data.X))
                    what = f"JointFeatures ({joints}, {stats} statistics)"
                    rows.append(_row(what, "numpy", n_frames, wall, cpu))
            n_gen = 200 if quick else 1000
            wall, cpu = _median(
                lambda: make_gesture_streams(n_gen, random_state=1), repeat=3, warmup=0
            )
            gen = make_gesture_streams(n_gen, random_state=1)
            gen_frames = sum(len(x) for x in gen.X)
            rows.append(
                _row(f"make_gesture_streams({n_gen})", "", gen_frames, wall, cpu)
            )
    finally:
        descriptor_module.USE_COMPILED = before
    return rows


COLUMNS = [
    "what",
    "path",
    "frames",
    "median s",
    "frames/s",
    "frames/s (CPU)",
    "µs/frame (CPU)",
]

if __name__ == "__main__":
    from _common import format_table

    print(format_table(run(), COLUMNS, "Descriptor and generator speed (one core)"))
