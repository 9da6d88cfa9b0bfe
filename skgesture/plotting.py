"""Figures of gesture streams, segmentations, confusions and skeletons.

Every function draws with matplotlib (``pip install skgesture[plot]``), which is
imported only when a function is called, and returns the matplotlib ``Axes`` it
drew on; most take ``ax=`` to draw into an existing figure. The figures follow
the paper's: the segmentation view of its Figure 4
(:func:`plot_segmentation`), the frame confusion matrix of its Figure 5
(:func:`plot_confusion_matrix`) and the truth-against-prediction timelines of its
Figure 7 (:func:`plot_timelines`), plus a single-sequence timeline with a score
track (:func:`plot_gesture_timeline`) and a skeleton pose
(:func:`plot_skeleton`). See ``docs/method.md`` for the methods they show.

Every figure draws a class in the same colour. Classes 1-10 get the ten hues
of matplotlib's ``tab10`` (the dark shades of ``tab20``), classes 11-20 the
light shades of the same hues, classes 21-56 the colours of ``tab20b`` and
``tab20c`` (less its greys, too close to rest), one shade of each hue in turn;
from class 57 the colours repeat. So two classes in a row never share a hue
(classes ``2k - 1`` and ``2k``, often the two halves of a gesture pair, are
told apart at a glance), and the first 56 classes never share a colour. Rest
is light grey: the background of the timeline bars, and the first entry of
their legends.
"""

# SPDX-License-Identifier: BSD-3-Clause

import numpy as np

from skgesture.utils._segments import labels_to_segments

__all__ = [
    "plot_confusion_matrix",
    "plot_gesture_timeline",
    "plot_segmentation",
    "plot_skeleton",
    "plot_timelines",
]

REST_NAME = "rest"
REST_COLOUR = "0.93"  # light grey: the background of a bar, where nobody gestures
_PALETTE = []  # the class colours, filled on first use (see _class_colour)


def _pyplot():
    """``matplotlib.pyplot``, or an ImportError saying how to install it."""
    try:
        import matplotlib.pyplot as plt
    except ImportError as exc:  # pragma: no cover - matplotlib is a test extra
        raise ImportError(
            "skgesture.plotting needs matplotlib; install it with "
            "`pip install skgesture[plot]` (or `pip install matplotlib`)"
        ) from exc
    return plt


def _palette():
    """The 56 class colours, in the order of :func:`_class_colour`."""
    if not _PALETTE:
        import matplotlib as mpl

        tab20 = mpl.colormaps["tab20"].colors  # 10 hues, a dark and a light shade
        colours = [tab20[i] for i in range(0, 20, 2)]  # the dark ones (tab10)
        colours += [tab20[i] for i in range(1, 20, 2)]  # then the light ones
        # 5 hues of 4 shades each; tab20c's fifth hue is grey, too close to rest
        for name, n_hues in (("tab20b", 5), ("tab20c", 4)):
            shades = mpl.colormaps[name].colors
            for shade in (0, 2, 1, 3):
                colours += [shades[4 * hue + shade] for hue in range(n_hues)]
        _PALETTE.extend(tuple(c) for c in colours)
    return _PALETTE


def _class_colour(label):
    """The colour of class ``label`` (an RGB tuple); rest is light grey.

    Classes 1-10 get the ten hues of tab10 (the dark shades of tab20), classes
    11-20 the light shades of the same hues, classes 21-56 the colours of
    tab20b and tab20c (less its greys), one shade of each hue in turn; from
    class 57 the colours repeat. Two classes in a row (``2k - 1`` and ``2k``
    above all, often the two halves of a gesture pair) never share a hue, and
    the first 56 classes never share a colour.
    """
    label = int(label)
    if label == 0:
        return REST_COLOUR
    palette = _palette()
    return palette[(label - 1) % len(palette)]


def _class_name(label, target_names):
    label = int(label)
    if label == 0:
        return REST_NAME
    if target_names is not None and 1 <= label <= len(target_names):
        return str(target_names[label - 1])
    return str(label)


def _labels(y, name, n_frames=None):
    y = np.asarray(y)
    if y.ndim != 1:
        raise ValueError(f"{name} must be one label per frame, got shape {y.shape}")
    if n_frames is not None and len(y) != n_frames:
        raise ValueError(
            f"{name} has {len(y)} frames but the sequence has {n_frames} frames"
        )
    return y


def plot_gesture_timeline(
    y_true=None,
    y_pred=None,
    *,
    scores=None,
    threshold=None,
    fps=None,
    target_names=None,
    ax=None,
    title=None,
    legend=True,
):
    """Draw the gestures of one sequence as coloured bars, truth above prediction.

    Every maximal run of one class is a bar named after its class, on a light
    grey band that is rest; a score track (such as the segmenter's smoothed
    score) and its threshold can be drawn underneath. The legend names rest
    and every class present, in the class colours of the module docstring
    (classes ``2k - 1`` and ``2k`` never share a hue).

    Parameters
    ----------
    y_true : array-like of shape (n_frames,) or None, default=None
        True per-frame labels (0 = rest).
    y_pred : array-like of shape (n_frames,) or None, default=None
        Predicted per-frame labels.
    scores : array-like of shape (n_frames,) or None, default=None
        A score track drawn under the bars, e.g. the segmenter's smoothed
        gesture probability (``ActivitySegmenter.decision_function``).
    threshold : float or None, default=None
        Horizontal line drawn over ``scores``.
    fps : float or None, default=None
        Frames per second; the x axis is in seconds when given, else in frames.
    target_names : list of str or None, default=None
        Name of class ``k`` at index ``k - 1``, written on the bars.
    ax : matplotlib Axes or None, default=None
        Where to draw; a new figure when None.
    title : str or None, default=None
        Axes title.
    legend : bool, default=True
        Show a legend: rest, the classes present, and the score track.

    Returns
    -------
    matplotlib.axes.Axes
        The axes drawn on.

    See Also
    --------
    plot_timelines : Truth against prediction for several sequences.
    plot_segmentation : The segmenter's score, threshold and periods.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> from skgesture.plotting import plot_gesture_timeline
    >>> ax = plot_gesture_timeline([0, 1, 1, 0, 2, 2], [0, 1, 1, 1, 0, 2],
    ...                            target_names=["wave", "point"])
    >>> [t.get_text() for t in ax.get_yticklabels()]
    ['prediction', 'truth']
    >>> [t.get_text() for t in ax.get_legend().get_texts()]
    ['rest', 'wave', 'point']
    """
    plt = _pyplot()
    from matplotlib.patches import Patch, Rectangle

    rows = [
        (name, _labels(y, name_arg))
        for name, name_arg, y in (
            ("truth", "y_true", y_true),
            ("prediction", "y_pred", y_pred),
        )
        if y is not None
    ]
    if not rows and scores is None:
        raise ValueError("give at least one of y_true, y_pred or scores")
    if ax is None:
        _, ax = plt.subplots(figsize=(12, 1.2 + 0.6 * max(len(rows), 1)))
    scale = 1.0 / fps if fps else 1.0
    top = len(rows)
    present = set()
    for level, (name, y) in enumerate(rows):
        row = top - level  # truth on top
        ax.add_patch(
            Rectangle(
                (0, row - 0.4),
                len(y) * scale,
                0.8,
                facecolor=REST_COLOUR,
                linewidth=0,
                zorder=0.5,
            )
        )
        for c, s, e in labels_to_segments(y):
            present.add(int(c))
            ax.broken_barh(
                [(s * scale, (e - s) * scale)],
                (row - 0.4, 0.8),
                facecolors=_class_colour(c),
                edgecolor="black",
                linewidth=0.5,
            )
            ax.text(
                (s + e) / 2 * scale,
                row,
                _class_name(c, target_names),
                ha="center",
                va="center",
                fontsize=7,
                clip_on=True,
            )
    ticks = [top - level for level in range(len(rows))]
    ax.set_yticks(ticks[::-1], [name for name, _ in rows][::-1])
    n_frames = max([len(y) for _, y in rows] + [0])
    handles = []
    if rows:
        handles.append(Patch(facecolor=REST_COLOUR, label=REST_NAME))
        handles += [
            Patch(facecolor=_class_colour(c), label=_class_name(c, target_names))
            for c in sorted(present)
        ]
    if scores is not None:
        s = np.asarray(scores, dtype=float)
        n_frames = max(n_frames, len(s))
        t = np.arange(len(s)) * scale
        handles += ax.plot(
            t, s * 0.8 - 0.4, color="tab:gray", linewidth=1, label="score (0-1)"
        )
        if threshold is not None:
            handles.append(
                ax.axhline(
                    threshold * 0.8 - 0.4,
                    color="tab:red",
                    linestyle="--",
                    linewidth=0.8,
                    label=f"threshold {threshold}",
                )
            )
        ax.set_ylim(-0.5, top + 0.5)
    else:
        ax.set_ylim(0.5, top + 0.5)
    if legend and handles:
        ax.legend(
            handles=handles,
            loc="upper left",
            bbox_to_anchor=(1.01, 1.0),
            fontsize=7,
            frameon=False,
        )
    if n_frames:
        ax.set_xlim(0, n_frames * scale)
    ax.set_xlabel("time (s)" if fps else "frame")
    if title:
        ax.set_title(title)
    return ax


def plot_timelines(
    y_true,
    y_pred=None,
    *,
    sample_ids=None,
    target_names=None,
    fps=None,
    ax=None,
    title=None,
    legend=True,
):
    """Truth against prediction for every sequence, one band each (Figure 7).

    Each sequence is a band: its true gestures on the upper bar, the predicted
    ones on the lower bar, one colour per class. Misses, false alarms, late
    starts and merged gestures are seen at a glance.

    Parameters
    ----------
    y_true : list of array-like of shape (n_frames_i,)
        True per-frame labels of each sequence (0 = rest).
    y_pred : list of array-like of shape (n_frames_i,) or None, default=None
        Predicted per-frame labels; None draws the truth only.
    sample_ids : list of str or None, default=None
        Name of each sequence on the y axis (default: its index).
    target_names : list of str or None, default=None
        Name of class ``k`` at index ``k - 1``, used in the legend.
    fps : float or None, default=None
        Frames per second; the x axis is in seconds when given, else in frames.
    ax : matplotlib Axes or None, default=None
        Where to draw; a new figure sized for the sequences when None.
    title : str or None, default=None
        Axes title.
    legend : bool, default=True
        Show a legend: rest (the grey background of a bar) and the classes
        present, in the class colours of the module docstring (classes
        ``2k - 1`` and ``2k`` never share a hue).

    Returns
    -------
    matplotlib.axes.Axes
        The axes drawn on.

    See Also
    --------
    plot_gesture_timeline : One sequence, with a score track.
    plot_confusion_matrix : The frame confusions behind these timelines.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> from skgesture.plotting import plot_timelines
    >>> y_true = [[0, 1, 1, 1, 0, 0, 2, 2, 0], [0, 0, 3, 3, 3, 0]]
    >>> y_pred = [[0, 0, 1, 1, 0, 0, 2, 2, 2], [0, 0, 0, 3, 3, 0]]
    >>> ax = plot_timelines(y_true, y_pred, sample_ids=["take1", "take2"],
    ...                     target_names=["wave", "point", "stop"])
    >>> [t.get_text() for t in ax.get_yticklabels()]
    ['take2', 'take1']
    >>> [t.get_text() for t in ax.get_legend().get_texts()]
    ['rest', 'wave', 'point', 'stop']
    """
    plt = _pyplot()
    y_true = [_labels(y, f"y_true[{i}]") for i, y in enumerate(y_true)]
    n = len(y_true)
    if n == 0:
        raise ValueError("y_true holds no sequence")
    if y_pred is not None:
        if len(y_pred) != n:
            raise ValueError(f"y_true has {n} sequences but y_pred has {len(y_pred)}")
        y_pred = [
            _labels(p, f"y_pred[{i}]", len(t))
            for i, (p, t) in enumerate(zip(y_pred, y_true))
        ]
    if sample_ids is None:
        sample_ids = [str(i) for i in range(n)]
    elif len(sample_ids) != n:
        raise ValueError(f"{len(sample_ids)} sample_ids for {n} sequences")
    if ax is None:
        _, ax = plt.subplots(figsize=(12, 1.2 + 0.45 * n))
    scale = 1.0 / fps if fps else 1.0
    bar = 0.38 if y_pred is not None else 0.7
    present = set()
    for i in range(n):
        centre = n - 1 - i  # first sequence on top
        tracks = [(y_true[i], centre + (0.02 if y_pred is not None else -bar / 2))]
        if y_pred is not None:
            tracks.append((y_pred[i], centre - 0.02 - bar))
        for y, bottom in tracks:
            ax.broken_barh(
                [(0, len(y) * scale)],
                (bottom, bar),
                facecolors=REST_COLOUR,
                linewidth=0,
            )
            for c, s, e in labels_to_segments(y):
                present.add(int(c))
                ax.broken_barh(
                    [(s * scale, (e - s) * scale)],
                    (bottom, bar),
                    facecolors=_class_colour(c),
                    edgecolor="black",
                    linewidth=0.4,
                )
        if i:
            ax.axhline(centre + 0.5, color="0.6", linewidth=0.5)
    ax.set_yticks(range(n), [str(s) for s in sample_ids][::-1])
    ax.set_ylim(-0.5, n - 0.5)
    ax.set_xlim(0, max(len(y) for y in y_true) * scale)
    ax.set_xlabel("time (s)" if fps else "frame")
    if y_pred is not None:
        ax.set_ylabel("upper bar: truth, lower bar: prediction", fontsize=8)
    if legend:
        from matplotlib.patches import Patch

        handles = [Patch(facecolor=REST_COLOUR, label=REST_NAME)] + [
            Patch(facecolor=_class_colour(c), label=_class_name(c, target_names))
            for c in sorted(present)
        ]
        ax.legend(
            handles=handles,
            loc="upper left",
            bbox_to_anchor=(1.01, 1.0),
            fontsize=7,
            frameon=False,
        )
    if title:
        ax.set_title(title)
    return ax


def _find_segmenter(estimator):
    """``(prefix, segmenter)``: the stages before the segmenter and the segmenter."""
    from sklearn.pipeline import Pipeline

    from skgesture._segmenter import ActivitySegmenter

    if isinstance(estimator, ActivitySegmenter):
        return None, estimator
    if isinstance(estimator, Pipeline):
        for k, (_, step) in enumerate(estimator.steps):
            if isinstance(step, ActivitySegmenter):
                return (estimator[:k] if k else None), step
    raise ValueError(
        "plot_segmentation needs a fitted ActivitySegmenter or a pipeline holding "
        f"one (Methods A and B), got {type(estimator).__name__}"
    )


def plot_segmentation(
    estimator,
    x,
    y_true=None,
    *,
    fps=None,
    target_names=None,
    show_raw=True,
    ax=None,
    title=None,
):
    """The activity segmentation of one sequence (the paper's Figure 4).

    Draws the true gestures as shaded spans, the segmenter network's raw
    gesture probability (thin), its loess-smoothed score (thick), the
    threshold, and the periods of activity the segmenter keeps (bars under
    the curves): frames above the threshold in runs of at least
    ``min_length`` frames (``docs/method.md``, activity segmentation).

    Parameters
    ----------
    estimator : Pipeline or ActivitySegmenter
        A fitted Method A or B pipeline (the stages before its segmenter
        compute the features of ``x``), or a fitted :class:`ActivitySegmenter`
        (``x`` is then its input features).
    x : array-like of shape (n_frames, 20, 3) or (n_frames, n_features)
        One sequence.
    y_true : array-like of shape (n_frames,) or None, default=None
        True per-frame labels, shaded when given.
    fps : float or None, default=None
        Frames per second; the x axis is in seconds when given, else in frames.
    target_names : list of str or None, default=None
        Name of class ``k`` at index ``k - 1``, written on the shaded gestures.
    show_raw : bool, default=True
        Also draw the unsmoothed network output.
    ax : matplotlib Axes or None, default=None
        Where to draw; a new figure when None.
    title : str or None, default=None
        Axes title.

    Returns
    -------
    matplotlib.axes.Axes
        The axes drawn on.

    See Also
    --------
    skgesture.ActivitySegmenter : The stage drawn here.
    plot_gesture_timeline : The resulting labels against the truth.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> from sklearn.linear_model import LogisticRegression
    >>> from skgesture import make_method_a
    >>> from skgesture.plotting import plot_segmentation
    >>> from skgesture.utils._testing import make_skeleton_stream
    >>> X, y = make_skeleton_stream(random_state=0)
    >>> pipe = make_method_a(random_state=0).set_params(
    ...     segmenter__estimator=LogisticRegression(max_iter=1000))
    >>> segmentation = pipe[:2].fit([X], [y])  # descriptor and segmenter
    >>> ax = plot_segmentation(segmentation, X, y, fps=20)
    >>> [t.get_text() for t in ax.get_legend().get_texts()][:3]
    ['network output', 'smoothed score', 'threshold 0.4']
    """
    plt = _pyplot()
    prefix, seg = _find_segmenter(estimator)
    features = [np.asarray(x)] if prefix is None else prefix.transform([x])
    n_frames = len(features[0])
    raw = seg.predict_proba(features)[0][:, 1]
    smoothed = seg.decision_function(features)[0]
    active = seg.predict(features)[0]
    if ax is None:
        _, ax = plt.subplots(figsize=(12, 3.2))
    scale = 1.0 / fps if fps else 1.0
    t = np.arange(n_frames) * scale
    if y_true is not None:
        y_true = _labels(y_true, "y_true", n_frames)
        for k, (c, s, e) in enumerate(labels_to_segments(y_true)):
            ax.axvspan(
                s * scale,
                e * scale,
                color=_class_colour(c),
                alpha=0.3,
                linewidth=0,
                label="true gesture" if k == 0 else None,
            )
            ax.text(
                (s + e) / 2 * scale,
                1.04,
                _class_name(c, target_names),
                ha="center",
                va="bottom",
                fontsize=7,
                clip_on=True,
            )
    if show_raw:
        ax.plot(t, raw, color="0.55", linewidth=0.7, label="network output")
    ax.plot(t, smoothed, color="tab:blue", linewidth=1.6, label="smoothed score")
    ax.axhline(
        seg.threshold,
        color="tab:red",
        linestyle="--",
        linewidth=1,
        label=f"threshold {seg.threshold:g}",
    )
    periods = [(s, e) for c, s, e in labels_to_segments(active)]
    for k, (s, e) in enumerate(periods):
        ax.broken_barh(
            [(s * scale, (e - s) * scale)],
            (-0.14, 0.08),
            facecolors="tab:green",
            label="detected period" if k == 0 else None,
        )
    ax.set_ylim(-0.18, 1.14)
    ax.set_xlim(0, n_frames * scale)
    ax.set_yticks([0, 0.5, 1])
    ax.set_ylabel("gesture score")
    ax.set_xlabel("time (s)" if fps else "frame")
    # the legend lists curves first, then the shading and the periods
    handles, labels = ax.get_legend_handles_labels()
    order = sorted(
        range(len(labels)),
        key=lambda i: (
            ("true gesture", "detected period").index(labels[i])
            if labels[i] in ("true gesture", "detected period")
            else -1
        ),
    )
    ax.legend(
        [handles[i] for i in order],
        [labels[i] for i in order],
        loc="upper left",
        bbox_to_anchor=(1.01, 1.0),
        fontsize=7,
        frameon=False,
    )
    if title:
        ax.set_title(title)
    return ax


def plot_confusion_matrix(
    y_true,
    y_pred,
    *,
    labels=None,
    target_names=None,
    normalize=None,
    log_scale=True,
    annotate=None,
    ax=None,
    title=None,
    cmap="viridis",
):
    """Frame confusion matrix on a log colour scale (the paper's Figure 5).

    Rest frames usually outnumber the frames of any gesture by far; on a
    linear scale the rest cell would hide every confusion between gestures.
    The log colour scale shows both, and cells without any frame stay blank.

    Parameters
    ----------
    y_true : list of array-like of shape (n_frames_i,)
        True per-frame labels, 0 = rest.
    y_pred : list of array-like of shape (n_frames_i,)
        Predicted per-frame labels.
    labels : array-like or None, default=None
        Labels of the rows and columns, in this order; None takes every label
        present, sorted (rest first).
    target_names : list of str or None, default=None
        Name of class ``k`` at index ``k - 1`` (label 0 is ``"rest"``).
    normalize : {"true", "pred", "all"} or None, default=None
        As :func:`skgesture.metrics.frame_confusion_matrix`; None counts frames.
    log_scale : bool, default=True
        Logarithmic colour scale.
    annotate : bool or None, default=None
        Write the value in every non-empty cell; None does so for up to 21
        labels.
    ax : matplotlib Axes or None, default=None
        Where to draw; a new figure when None.
    title : str or None, default=None
        Axes title.
    cmap : str or Colormap, default="viridis"
        Colour map.

    Returns
    -------
    matplotlib.axes.Axes
        The axes drawn on.

    See Also
    --------
    skgesture.metrics.frame_confusion_matrix : The matrix drawn here.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> from skgesture.plotting import plot_confusion_matrix
    >>> y_true = [[0] * 50 + [1] * 5 + [2] * 4]
    >>> y_pred = [[0] * 48 + [1] * 7 + [2, 1, 2, 2]]
    >>> ax = plot_confusion_matrix(y_true, y_pred, target_names=["wave", "point"])
    >>> [t.get_text() for t in ax.get_xticklabels()]
    ['rest', 'wave', 'point']
    """
    plt = _pyplot()
    from matplotlib.colors import LogNorm, Normalize

    from skgesture.metrics import frame_confusion_matrix

    cm = frame_confusion_matrix(y_true, y_pred, labels=labels, normalize=normalize)
    if labels is None:
        flat = np.concatenate(
            [np.asarray(y).ravel() for y in list(y_true) + list(y_pred)]
        )
        labels = np.unique(flat)
    labels = np.asarray(labels)
    k = len(labels)
    if ax is None:
        size = min(4 + 0.35 * k, 14)
        _, ax = plt.subplots(figsize=(size + 1.2, size))
    values = np.ma.masked_less_equal(cm.astype(float), 0)
    positive = values.compressed()
    vmax = positive.max() if positive.size else 1.0
    vmin = positive.min() if positive.size else 1.0
    if log_scale:
        norm = LogNorm(vmin=vmin, vmax=max(vmax, vmin * 10))
    else:
        norm = Normalize(vmin=0, vmax=vmax)
    colours = plt.get_cmap(cmap).with_extremes(bad="white")
    image = ax.imshow(values, norm=norm, cmap=colours, interpolation="nearest")
    colorbar = ax.figure.colorbar(image, ax=ax, fraction=0.046, pad=0.04)
    what = "fraction" if normalize else "frames"
    colorbar.set_label(f"{what} (log scale)" if log_scale else what)
    names = [_class_name(c, target_names) for c in labels]
    ax.set_xticks(range(k), names, rotation=60 if k > 6 else 0, ha="right")
    ax.set_yticks(range(k), names)
    if k > 6:
        ax.tick_params(axis="x", labelrotation=60)
        for tick in ax.get_xticklabels():
            tick.set_horizontalalignment("right")
    ax.set_xlabel("predicted")
    ax.set_ylabel("true")
    if annotate is None:
        annotate = k <= 21
    if annotate:
        fontsize = 8 if k <= 10 else 6
        middle = np.sqrt(vmin * vmax) if log_scale else vmax / 2
        for i in range(k):
            for j in range(k):
                v = cm[i, j]
                if v <= 0:
                    continue
                text = f"{v:.2f}" if normalize else f"{int(v)}"
                ax.text(
                    j,
                    i,
                    text,
                    ha="center",
                    va="center",
                    fontsize=fontsize,
                    color="white" if v < middle else "black",
                )
    if title:
        ax.set_title(title)
    return ax


def _side_colour(parent, child):
    names = parent + child
    if "Left" in names or "left" in names:
        return "tab:blue"
    if "Right" in names or "right" in names:
        return "tab:red"
    return "0.2"


def plot_skeleton(
    frame,
    *,
    layout=None,
    view="front",
    show_names=False,
    ax=None,
    title=None,
):
    """Draw the joints and bones of one skeleton frame.

    Left limbs are blue, right limbs red (the subject's left and right), the
    spine and head dark grey.

    Parameters
    ----------
    frame : array-like of shape (n_joints, 3) or (n_joints * 3,)
        Joint positions in camera space (x to the camera's left, y up, z away
        from the camera), e.g. one frame of a loader's ``X``.
    layout : SkeletonLayout or None, default=None
        The joint order and bones; None is the Kinect v1 layout
        (``skgesture.layouts.KINECT_V1``), which every model uses.
    view : {"front", "side", "top", "3d"}, default="front"
        Projection: as the camera sees the subject (x, y; the subject's left
        on the right of the figure), from the side (z, y), from above (x, z),
        or a 3-D view.
    show_names : bool, default=False
        Write the joint names.
    ax : matplotlib Axes or None, default=None
        Where to draw (a 3-D Axes for ``view="3d"``); a new figure when None.
    title : str or None, default=None
        Axes title.

    Returns
    -------
    matplotlib.axes.Axes
        The axes drawn on.

    Raises
    ------
    ValueError
        If the frame's shape does not fit the layout, or the frame is
        untracked (all zeros or NaN).

    See Also
    --------
    skgesture.layouts.SkeletonLayout : Joint names and bones.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> from skgesture.plotting import plot_skeleton
    >>> from skgesture.utils._testing import make_skeleton_stream
    >>> X, _ = make_skeleton_stream(random_state=0)
    >>> ax = plot_skeleton(X[0])
    >>> len(ax.lines)  # one line per bone
    19
    """
    plt = _pyplot()
    from skgesture.layouts import KINECT_V1

    layout = KINECT_V1 if layout is None else layout
    views = {"front": (0, 1), "side": (2, 1), "top": (0, 2), "3d": None}
    if view not in views:
        raise ValueError(f"view must be one of {sorted(views)}, got {view!r}")
    P = np.asarray(frame, dtype=float)
    if P.ndim == 1 and P.size == 3 * layout.n_joints:
        P = P.reshape(layout.n_joints, 3)
    if P.shape != (layout.n_joints, 3):
        raise ValueError(
            f"frame must have shape ({layout.n_joints}, 3) for layout "
            f"{layout.name!r}, got {np.shape(frame)}"
        )
    if not np.isfinite(P).all() or not P.any():
        raise ValueError("the frame is untracked (all zeros or NaN): nothing to draw")
    if ax is None:
        fig = plt.figure(figsize=(5.5, 5.5) if view == "3d" else (4.5, 5.5))
        ax = fig.add_subplot(projection="3d" if view == "3d" else None)
    if view == "3d":
        # x right, z into the scene, y up
        coords = P[:, [0, 2, 1]]
    else:
        coords = P[:, list(views[view])]
    for parent, child in layout.bones:
        a, b = layout.index(parent), layout.index(child)
        seg = coords[[a, b]].T
        ax.plot(*seg, color=_side_colour(parent, child), linewidth=2.2)
    ax.scatter(*coords.T, s=18, color="black", zorder=3)
    if show_names:
        for name, point in zip(layout.joint_names, coords):
            ax.text(*point, f" {name}", fontsize=6)
    if view == "3d":
        ax.set_xlabel("x (m)")
        ax.set_ylabel("z (m)")
        ax.set_zlabel("y (m)")
        span = (coords.max(axis=0) - coords.min(axis=0)).max() / 2
        centre = (coords.max(axis=0) + coords.min(axis=0)) / 2
        ax.set_xlim(centre[0] - span, centre[0] + span)
        ax.set_ylim(centre[1] - span, centre[1] + span)
        ax.set_zlim(centre[2] - span, centre[2] + span)
        ax.set_box_aspect((1, 1, 1))
    else:
        axis_names = "xyz"
        h, v = views[view]
        ax.set_xlabel(f"{axis_names[h]} (m)")
        ax.set_ylabel(f"{axis_names[v]} (m)")
        ax.set_aspect("equal", adjustable="datalim")
        ax.grid(True, linewidth=0.3, alpha=0.5)
        if h == 0:
            ax.invert_xaxis()  # x points to the camera's left: show its view
    if title:
        ax.set_title(title)
    return ax
