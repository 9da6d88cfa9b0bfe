"""skgesture.plotting: what each figure draws, on the Agg backend."""

import builtins
import importlib
import sys

import numpy as np
import pytest

matplotlib = pytest.importorskip("matplotlib")
matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.colors import LogNorm, rgb_to_hsv, to_rgb  # noqa: E402
from sklearn.linear_model import LogisticRegression  # noqa: E402

from skgesture import make_method_a  # noqa: E402
from skgesture.datasets import make_gesture_streams  # noqa: E402
from skgesture.layouts import KINECT_V1  # noqa: E402
from skgesture.plotting import (  # noqa: E402
    _class_colour,
    plot_confusion_matrix,
    plot_gesture_timeline,
    plot_segmentation,
    plot_skeleton,
    plot_timelines,
)
from skgesture.utils._segments import labels_to_segments  # noqa: E402


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


@pytest.fixture(scope="module")
def streams():
    return make_gesture_streams(
        n_sequences=2, n_classes=3, n_gestures=(3, 3), random_state=0
    )


@pytest.fixture(scope="module")
def segmentation(streams):
    # The descriptor and segmenter stages of Method A, a logistic regression
    # standing in for the network: the figure is the point.
    return (
        make_method_a(random_state=0)[:2]
        .set_params(segmenter__estimator=LogisticRegression(max_iter=1000))
        .fit(streams.X, streams.y)
    )


def _bars(ax):
    """``(x, width, y)`` of every bar drawn by ``broken_barh``."""
    out = []
    for coll in ax.collections:
        for path in coll.get_paths():
            v = path.vertices
            out.append((v[:, 0].min(), np.ptp(v[:, 0]), v[:, 1].min()))
    return out


def test_missing_matplotlib_says_how_to_install(monkeypatch):
    real_import = builtins.__import__

    def no_matplotlib(name, *args, **kwargs):
        if name == "matplotlib" or name.startswith("matplotlib."):
            raise ImportError("No module named 'matplotlib'")
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", no_matplotlib)
    for name in [m for m in sys.modules if m.startswith("matplotlib")]:
        monkeypatch.delitem(sys.modules, name)
    plotting = importlib.reload(sys.modules["skgesture.plotting"])  # imports fine
    with pytest.raises(ImportError, match=r"pip install skgesture\[plot\]"):
        plotting.plot_gesture_timeline([0, 1, 1, 0])


def test_gesture_timeline_bars_follow_the_labels():
    ax = plot_gesture_timeline([0, 1, 1, 0, 2, 2], [0, 1, 1, 1, 0, 2], fps=2)
    bars = sorted(_bars(ax))
    # truth row (y 1.6..2.4): [1, 3) and [4, 6); prediction row: [1, 4) and [5, 6)
    truth = [(x, w) for x, w, y in bars if y > 1.5]
    pred = [(x, w) for x, w, y in bars if y < 1.5]
    assert truth == [(0.5, 1.0), (2.0, 1.0)]
    assert pred == [(0.5, 1.5), (2.5, 0.5)]
    assert ax.get_xlabel() == "time (s)"
    with pytest.raises(ValueError, match="at least one"):
        plot_gesture_timeline()


def _legend(ax):
    """``{label: facecolour}`` of the legend's patches, in legend order."""
    leg = ax.get_legend()
    # legend_handles from matplotlib 3.7 on; legendHandles before (the floor, 3.6)
    handles = getattr(leg, "legend_handles", None) or leg.legendHandles
    return {
        t.get_text(): to_rgb(h.get_facecolor())
        for t, h in zip(leg.get_texts(), handles)
        if hasattr(h, "get_facecolor")
    }


def test_gesture_timeline_legend_names_rest_and_the_classes_present():
    names = ["wave", "point", "stop", "kick"]
    ax = plot_gesture_timeline(
        [0, 1, 1, 0, 2, 2, 0], [0, 1, 1, 1, 0, 4, 0], target_names=names
    )
    legend = _legend(ax)
    assert list(legend) == ["rest", "wave", "point", "kick"]  # not "stop": absent
    assert legend["rest"] == to_rgb("0.93")
    for k, name in ((1, "wave"), (2, "point"), (4, "kick")):
        assert legend[name] == to_rgb(_class_colour(k))
    # the bars are drawn in the legend's colours
    bar_colours = {to_rgb(c.get_facecolor()[0]) for c in ax.collections}
    assert bar_colours == {legend[n] for n in ("wave", "point", "kick")}
    # with a score track the legend lists the curves after the classes
    ax = plot_gesture_timeline([0, 1, 1, 0], scores=[0, 0.9, 0.8, 0.1], threshold=0.5)
    texts = [t.get_text() for t in ax.get_legend().get_texts()]
    assert texts == ["rest", "1", "score (0-1)", "threshold 0.5"]
    assert plot_gesture_timeline([0, 1, 1], legend=False).get_legend() is None


@pytest.mark.parametrize("n_classes", [20, 56])
def test_no_two_classes_share_a_colour_and_neighbours_differ_in_hue(n_classes):
    """Classes 2k - 1 and 2k (any two in a row) differ in hue, not only in
    shade (tab20 in its own order gave them a dark and a light blue)."""
    colours = [to_rgb(_class_colour(k)) for k in range(1, n_classes + 1)]
    assert len(set(colours)) == n_classes
    assert to_rgb(_class_colour(0)) not in colours  # rest
    hsv = rgb_to_hsv(np.array(colours))
    for k in range(n_classes - 1):
        (h1, s1, v1), (h2, s2, v2) = hsv[k], hsv[k + 1]
        if min(s1, s2) < 0.05:  # a grey: told apart by saturation or value
            assert max(abs(s1 - s2), abs(v1 - v2)) >= 0.2, (k + 1, k + 2)
        else:
            dh = abs(h1 - h2)
            assert min(dh, 1 - dh) * 360 >= 20, (k + 1, k + 2)
    # the timelines draw the same colours, each class in its own
    y = [np.repeat(np.arange(n_classes + 1), 3)]
    ax = plot_timelines(y)
    legend = _legend(ax)
    assert len(legend) == n_classes + 1 and len(set(legend.values())) == n_classes + 1


def test_timelines_one_band_per_sequence():
    y_true = [[0, 1, 1, 0, 0], [0, 0, 2, 2, 2, 0, 3]]
    y_pred = [[0, 1, 1, 1, 0], [0, 0, 0, 2, 2, 0, 0]]
    ax = plot_timelines(y_true, y_pred, sample_ids=["a", "b"], target_names="xyz")
    assert [t.get_text() for t in ax.get_yticklabels()] == ["b", "a"]
    gestures = [b for b in _bars(ax) if b[1] < 5]  # not the grey backgrounds
    # 2 true + 1 predicted gestures for "a"... 2 true + 1 predicted for "b"
    assert len(gestures) == sum(
        len(labels_to_segments(np.asarray(y))) for y in y_true + y_pred
    )
    legend = [t.get_text() for t in ax.get_legend().get_texts()]
    assert legend == ["rest", "x", "y", "z"]
    with pytest.raises(ValueError, match="y_pred\\[1\\] has 3 frames"):
        plot_timelines(y_true, [y_pred[0], [0, 0, 0]])
    with pytest.raises(ValueError, match="2 sequences but y_pred has 1"):
        plot_timelines(y_true, y_pred[:1])


def test_segmentation_shows_score_threshold_and_periods(segmentation, streams):
    x, y = streams.X[0], streams.y[0]
    ax = plot_segmentation(segmentation, x, y, target_names=streams.target_names)
    seg = segmentation.named_steps["segmenter"]
    D = segmentation[:1].transform([x])
    lines = {line.get_label(): line for line in ax.get_lines()}
    np.testing.assert_allclose(
        lines["smoothed score"].get_ydata(), seg.decision_function(D)[0]
    )
    assert lines[f"threshold {seg.threshold:g}"].get_ydata()[0] == seg.threshold
    periods = labels_to_segments(seg.predict(D)[0])
    drawn = sorted((x0, w) for x0, w, y0 in _bars(ax) if y0 < 0)
    assert drawn == [(s, e - s) for _, s, e in periods]
    shaded = [p for p in ax.patches if p.get_label() != "detected period"]
    assert len(shaded) == len(labels_to_segments(y))
    with pytest.raises(ValueError, match="ActivitySegmenter"):
        plot_segmentation(LogisticRegression(), x)


def test_confusion_matrix_uses_a_log_scale_and_leaves_zeros_blank():
    y_true = [np.r_[np.zeros(500, int), np.ones(20, int), np.full(10, 2)]]
    y_pred = [np.r_[np.zeros(490, int), np.ones(30, int), np.full(10, 2)]]
    ax = plot_confusion_matrix(y_true, y_pred, target_names=["wave", "point"])
    image = ax.get_images()[0]
    assert isinstance(image.norm, LogNorm)
    data = image.get_array()
    assert data[0, 0] == 490 and data[0, 1] == 10 and data[1, 1] == 20
    assert data.mask[0, 2] and data.mask[2, 0]  # no frame: blank
    texts = sorted(t.get_text() for t in ax.texts)
    assert texts == ["10", "10", "20", "490"]
    linear = plot_confusion_matrix(y_true, y_pred, log_scale=False)
    assert not isinstance(linear.get_images()[0].norm, LogNorm)


def test_skeleton_draws_every_bone(streams):
    frame = next(f for f in streams.X[0] if f.any())  # a tracked frame
    ax = plot_skeleton(frame, show_names=True)
    assert len(ax.lines) == len(KINECT_V1.bones)
    head = KINECT_V1.index("Head")
    assert any(t.get_text().strip() == "Head" for t in ax.texts)
    xy = ax.collections[0].get_offsets()
    np.testing.assert_allclose(xy[head], frame[head, :2])
    assert ax.xaxis_inverted()  # as the camera sees the subject
    ax3 = plot_skeleton(frame.ravel(), view="3d")
    assert ax3.name == "3d"
    with pytest.raises(ValueError, match="untracked"):
        plot_skeleton(np.zeros((20, 3)))
    with pytest.raises(ValueError, match=r"shape \(20, 3\)"):
        plot_skeleton(np.ones((3, 20)))
    with pytest.raises(ValueError, match="view must be"):
        plot_skeleton(frame, view="back")


def test_figures_render_to_png(segmentation, streams, tmp_path):
    # the full figures render (text layout, legends, colour bars) without error
    pred = [np.roll(y, 5) for y in streams.y]  # a prediction a little late
    axes = [
        plot_segmentation(segmentation, streams.X[1], streams.y[1], fps=streams.fps),
        plot_timelines(streams.y, pred, fps=streams.fps),
        plot_confusion_matrix(streams.y, pred),
        plot_skeleton(next(f for f in streams.X[0] if f.any()), view="side"),
    ]
    for k, ax in enumerate(axes):
        path = tmp_path / f"{k}.png"
        ax.figure.savefig(path)
        assert path.read_bytes().startswith(b"\x89PNG")
