"""Speed of the PoseDescriptor and of the synthetic stream generator (issue 2)."""

from _common import median_time, one_core

from skgesture import PoseDescriptor
from skgesture.datasets import make_gesture_streams

SHORT_FRAMES = 60  # length of the short sequences of the per-sequence overhead row


def run(quick=False):
    """Rows: descriptor frames/s on one core per joint set; generator speed."""
    n_seq = 20 if quick else 100
    data = make_gesture_streams(n_seq, random_state=0)
    n_frames = sum(len(x) for x in data.X)
    rows = []
    with one_core():
        for joints in ("paper11", "full20"):
            desc = PoseDescriptor(joints=joints).fit(data.X)
            med, times = median_time(lambda: desc.transform(data.X), repeat=5)
            rows.append(
                {
                    "what": f"PoseDescriptor ({joints}, {desc.n_features_out_}-D)",
                    "frames": n_frames,
                    "median s": med,
                    "frames/s": n_frames / med,
                    "µs/frame": 1e6 * med / n_frames,
                }
            )
        # The same frames as many short sequences: per-sequence overhead.
        short = [
            x[i : i + SHORT_FRAMES]
            for x in data.X
            for i in range(0, len(x) - SHORT_FRAMES + 1, SHORT_FRAMES)
        ]
        n_short = sum(len(x) for x in short)
        desc = PoseDescriptor().fit(data.X)
        med, _ = median_time(lambda: desc.transform(short), repeat=5)
        rows.append(
            {
                "what": f"PoseDescriptor (paper11, {SHORT_FRAMES}-frame sequences)",
                "frames": n_short,
                "median s": med,
                "frames/s": n_short / med,
                "µs/frame": 1e6 * med / n_short,
            }
        )
        n_gen = 200 if quick else 1000
        med, _ = median_time(
            lambda: make_gesture_streams(n_gen, random_state=1), repeat=3, warmup=0
        )
        gen = make_gesture_streams(n_gen, random_state=1)
        gen_frames = sum(len(x) for x in gen.X)
        rows.append(
            {
                "what": f"make_gesture_streams({n_gen})",
                "frames": gen_frames,
                "median s": med,
                "frames/s": gen_frames / med,
                "µs/frame": 1e6 * med / gen_frames,
            }
        )
    return rows


COLUMNS = ["what", "frames", "median s", "frames/s", "µs/frame"]

if __name__ == "__main__":
    from _common import format_table

    print(format_table(run(), COLUMNS, "Descriptor and generator speed (one core)"))
