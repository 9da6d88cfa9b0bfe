"""Plots of gesture streams: label timelines and score tracks (needs matplotlib)."""

# SPDX-License-Identifier: BSD-3-Clause

import numpy as np

from skgesture.utils._segments import labels_to_segments

__all__ = ["plot_gesture_timeline"]


def _class_colour(label, n_colours=20):
    import matplotlib as mpl

    return mpl.colormaps["tab20"]((int(label) - 1) % n_colours)


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
):
    """Draw the gestures of one sequence as coloured bars, truth above prediction.

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

    Returns
    -------
    matplotlib.axes.Axes
        The axes drawn on.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> from skgesture.plotting import plot_gesture_timeline
    >>> ax = plot_gesture_timeline([0, 1, 1, 0, 2, 2], [0, 1, 1, 1, 0, 2])
    >>> [t.get_text() for t in ax.get_yticklabels()]
    ['prediction', 'truth']
    """
    import matplotlib.pyplot as plt

    rows = [
        (name, y)
        for name, y in (("truth", y_true), ("prediction", y_pred))
        if y is not None
    ]
    if not rows and scores is None:
        raise ValueError("give at least one of y_true, y_pred or scores")
    if ax is None:
        _, ax = plt.subplots(figsize=(12, 1.2 + 0.6 * len(rows)))
    scale = 1.0 / fps if fps else 1.0
    top = len(rows)
    for level, (name, y) in enumerate(rows):
        row = top - level  # truth on top
        for c, s, e in labels_to_segments(np.asarray(y)):
            ax.broken_barh(
                [(s * scale, (e - s) * scale)],
                (row - 0.4, 0.8),
                facecolors=_class_colour(c),
                edgecolor="black",
                linewidth=0.5,
            )
            label = target_names[c - 1] if target_names is not None else str(c)
            ax.text(
                (s + e) / 2 * scale,
                row,
                label,
                ha="center",
                va="center",
                fontsize=7,
                clip_on=True,
            )
    ticks = [top - level for level in range(len(rows))]
    ax.set_yticks(ticks[::-1], [name for name, _ in rows][::-1])
    if scores is not None:
        s = np.asarray(scores, dtype=float)
        t = np.arange(len(s)) * scale
        ax.plot(
            t, s * 0.8 - 0.4 + 0.0, color="tab:gray", linewidth=1, label="score (0-1)"
        )
        if threshold is not None:
            ax.axhline(
                threshold * 0.8 - 0.4,
                color="tab:red",
                linestyle="--",
                linewidth=0.8,
                label=f"threshold {threshold}",
            )
        ax.legend(loc="upper right", fontsize=7)
        ax.set_ylim(-0.5, top + 0.5)
    else:
        ax.set_ylim(0.5, top + 0.5)
    ax.set_xlabel("time (s)" if fps else "frame")
    if title:
        ax.set_title(title)
    return ax
