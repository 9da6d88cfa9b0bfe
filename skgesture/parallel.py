"""Prediction over many recordings, on one machine or a Dask cluster.

:func:`predict_files` runs a fitted model over a folder of recordings, one
task per file: each task reads its file, predicts and returns the result (or
writes it next to the others), so no process ever holds more than the
recordings it is working on. Without a Dask client it runs in this process;
with one (or a scheduler address) the tasks run on the cluster's workers.
:func:`local_cluster` starts a small Dask cluster on this machine and shuts it
down cleanly. Searches and cross-validation need nothing from this module:
``with joblib.parallel_backend("dask"): search.fit(X, y)`` runs the fits of a
``GridSearchCV`` on the cluster of the current Dask client.

Dask is optional: ``pip install "skgesture[dask]"``. See ``docs/scale.md``.
"""

# SPDX-License-Identifier: BSD-3-Clause

import asyncio
import glob
import os
from contextlib import contextmanager
from pathlib import Path

import numpy as np

__all__ = ["close_cluster", "local_cluster", "predict_files", "read_recording"]

# Suffixes read_recording understands, and those a folder is searched for.
RECORDING_SUFFIXES = (".npy", ".csv", ".tsv", ".txt")
CLOSE_TIMEOUT = 60  # seconds a worker process may take to exit (see close_cluster)
_DASK_HINT = 'install Dask with: pip install "skgesture[dask]"'


def read_recording(path):
    """Read one skeleton recording: ``.npy`` or a CSV/TSV skeleton file.

    The default reader of :func:`predict_files`.

    Parameters
    ----------
    path : str or path-like
        A ``.npy`` file holding an ``(n_frames, 20, 3)`` array (Kinect v1
        joints, metres), or a text file read by
        :func:`skgesture.datasets.read_skeleton_csv` (one frame per line).

    Returns
    -------
    ndarray of shape (n_frames, 20, 3)
        The frames, float64.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> import numpy as np
    >>> from skgesture.parallel import read_recording
    >>> tmp = tempfile.TemporaryDirectory()
    >>> np.save(Path(tmp.name) / "a.npy", np.ones((5, 20, 3)))
    >>> read_recording(Path(tmp.name) / "a.npy").shape
    (5, 20, 3)
    >>> tmp.cleanup()
    """
    path = Path(path)
    if path.suffix.lower() == ".npy":
        X = np.load(path, allow_pickle=False)
        if X.ndim != 3 or X.shape[1:] != (20, 3):
            raise ValueError(
                f"{path} holds an array of shape {X.shape}; expected "
                f"(n_frames, 20, 3) Kinect v1 joints"
            )
        return np.asarray(X, dtype=np.float64)
    from skgesture.datasets import read_skeleton_csv

    return read_skeleton_csv(path)


def _recording_paths(paths):
    """The files of ``paths``: a folder (its recordings, sorted), a glob
    pattern, one file, or a list of files."""
    if isinstance(paths, (str, os.PathLike)):
        p = Path(paths)
        if p.is_dir():
            files = sorted(
                f for f in p.iterdir() if f.suffix.lower() in RECORDING_SUFFIXES
            )
            if not files:
                raise FileNotFoundError(
                    f"{p} holds no recording ({', '.join(RECORDING_SUFFIXES)})"
                )
            return [str(f) for f in files]
        if p.is_file():
            return [str(p)]
        files = sorted(glob.glob(str(paths)))
        if not files:
            raise FileNotFoundError(f"no file matches {str(paths)!r}")
        return files
    files = [str(Path(f)) for f in paths]
    if not files:
        raise ValueError("paths is empty: give a folder, a pattern or files")
    return files


def _method(estimator, method):
    """``estimator.method``; for a Pipeline without it, its last step's method
    on the output of the other steps (e.g. ``predict_segments``)."""
    func = getattr(estimator, method, None)
    if callable(func):
        return func
    steps = getattr(estimator, "steps", None)
    if steps and callable(getattr(steps[-1][1], method, None)):
        last = getattr(steps[-1][1], method)
        return lambda X: last(estimator[:-1].transform(X))
    raise ValueError(
        f"{type(estimator).__name__} has no method {method!r} to call on the recordings"
    )


def _predict_one(estimator, path, reader, method, output_dir):
    """One task: read ``path``, predict, return the result or where it went."""
    X = reader(path)
    result = _method(estimator, method)([X])[0]
    if output_dir is None:
        return result
    out = Path(output_dir) / (Path(path).stem + f".{method}.npy")
    np.save(out, np.asarray(result))
    return str(out)


def _client(client):
    """A ``distributed.Client`` from a client or a scheduler address, and
    whether this call created it (and must close it)."""
    try:
        from distributed import Client
    except ImportError as exc:
        raise ImportError(
            f"predict_files(client=...) runs on Dask, which is not installed; "
            f"{_DASK_HINT}, or leave client=None to predict in this process"
        ) from exc
    if isinstance(client, Client):
        return client, False
    if isinstance(client, str):
        return Client(client), True
    raise TypeError(
        f"client must be None, a distributed.Client or a scheduler address such "
        f"as 'tcp://10.0.0.5:8786', got {type(client).__name__}"
    )


def predict_files(
    estimator,
    paths,
    *,
    reader=None,
    method="predict",
    client=None,
    output_dir=None,
    verbose=0,
):
    """Predict every recording of a folder, one task per file, on Dask or here.

    Each task reads one file with ``reader``, calls
    ``getattr(estimator, method)([X])`` and returns the result for that
    recording, or saves it as ``<output_dir>/<file stem>.<method>.npy`` and
    returns that path. Only the recordings being predicted are in memory;
    with ``output_dir`` the results are not gathered either.

    Parameters
    ----------
    estimator : fitted estimator
        A model taking a list of sequences (e.g. a fitted ``make_method_b()``
        pipeline). It is sent once to every worker.
    paths : str, path-like or list of them
        A folder (its ``.npy``, ``.csv``, ``.tsv`` and ``.txt`` files, sorted
        by name), a glob pattern such as ``"data/*.csv"``, or a list of files.
        On a cluster the workers open the files: the paths must be valid
        there (a shared file system).
    reader : callable or None, default=None
        ``reader(path) -> ndarray`` of one recording; ``None`` uses
        :func:`read_recording`. It must be importable on the workers (a
        module-level function, not a lambda defined in ``__main__`` of a
        script run elsewhere).
    method : str, default="predict"
        The method called, e.g. ``"predict_segments"`` (for a pipeline whose
        last step has it: that step's, on the output of the others).
    client : None, distributed.Client or str, default=None
        ``None`` predicts in this process, file after file (no Dask needed).
        A ``Client``, or the address of a Dask scheduler (``"tcp://host:8786"``,
        then a client is opened and closed here), runs the tasks on that
        cluster.
    output_dir : str, path-like or None, default=None
        Save each result there instead of returning it (the folder is
        created).
    verbose : int, default=0
        1 shows a progress bar over the files.

    Returns
    -------
    list
        One entry per file, in the order of the files: the result of
        ``method`` for that recording, or the path of the saved result.

    Raises
    ------
    ImportError
        When ``client`` is given and Dask is not installed (the message names
        the ``skgesture[dask]`` extra).

    See Also
    --------
    local_cluster : A Dask cluster on this machine, shut down cleanly.

    Notes
    -----
    ``docs/scale.md`` shows the same call on a cluster (``client=`` a
    scheduler address) and how to size the workers: one thread per worker
    suits the toolkit's models, which run torch on one thread.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> import numpy as np
    >>> from skgesture import PoseDescriptor
    >>> from skgesture.parallel import predict_files
    >>> from skgesture.utils._testing import make_skeleton_stream
    >>> tmp = tempfile.TemporaryDirectory()
    >>> for i in range(3):
    ...     X, _ = make_skeleton_stream(random_state=i)
    ...     np.save(Path(tmp.name) / f"rec{i}.npy", X)
    >>> desc = PoseDescriptor().fit([make_skeleton_stream(random_state=9)[0]])
    >>> out = predict_files(desc, tmp.name, method="transform")
    >>> [z.shape[1] for z in out]
    [183, 183, 183]
    >>> tmp.cleanup()
    """
    files = _recording_paths(paths)
    reader = read_recording if reader is None else reader
    if output_dir is not None:
        Path(output_dir).mkdir(parents=True, exist_ok=True)
        output_dir = str(output_dir)
    _method(estimator, method)  # fails early on a method the model lacks
    from tqdm.auto import tqdm

    bar = tqdm(total=len(files), unit="file", desc="predict_files", disable=verbose < 1)
    if client is None:
        out = []
        for path in files:
            out.append(_predict_one(estimator, path, reader, method, output_dir))
            bar.update(1)
        bar.close()
        return out
    client, owned = _client(client)
    try:
        from distributed import as_completed

        # The model goes to every worker once (not into each task's graph).
        [model] = client.scatter([estimator], broadcast=True, hash=False)
        futures = client.map(
            _predict_one,
            [model] * len(files),
            files,
            reader=reader,
            method=method,
            output_dir=output_dir,
            pure=False,
        )
        for _ in as_completed(futures):  # results stay on the workers until gather
            bar.update(1)
        bar.close()
        return client.gather(futures)
    finally:
        if owned:
            client.close()


async def _close_workers(workers, timeout):
    await asyncio.gather(*(w.close(timeout=timeout) for w in workers))


def close_cluster(cluster, client=None, *, timeout=CLOSE_TIMEOUT):
    """Shut a ``LocalCluster`` down without killing its worker processes.

    ``LocalCluster.close`` gives every worker process 4 seconds to exit, then
    kills it with the warning "Worker process still alive after 4.0 seconds,
    killing": a worker that imported torch can take longer than that to exit
    on a busy machine. This closes the client, then the workers with
    ``timeout`` seconds each (all at once), then the cluster.

    Parameters
    ----------
    cluster : distributed.LocalCluster
        The cluster.
    client : distributed.Client or None, default=None
        Its client, closed first.
    timeout : float, default=60
        Seconds each worker may take to close.

    See Also
    --------
    local_cluster : Closes its cluster this way on leaving the ``with`` block.

    Examples
    --------
    >>> from skgesture.parallel import close_cluster
    >>> from distributed import Client, LocalCluster  # doctest: +SKIP
    >>> cluster = LocalCluster(n_workers=2, processes=True)  # doctest: +SKIP
    >>> client = Client(cluster)  # doctest: +SKIP
    >>> close_cluster(cluster, client, timeout=30)  # doctest: +SKIP
    """
    if client is not None:
        client.close()
    workers = [w for w in cluster.workers.values() if hasattr(w, "close")]
    if workers and getattr(cluster, "status", None) is not None:
        cluster.sync(_close_workers, workers, timeout)
    cluster.close()


@contextmanager
def local_cluster(n_workers=2, threads_per_worker=1, *, processes=False, **kwargs):
    """A Dask ``LocalCluster`` and its client, shut down cleanly on exit.

    Parameters
    ----------
    n_workers : int, default=2
        Number of workers.
    threads_per_worker : int, default=1
        Threads of each worker.
    processes : bool, default=False
        Workers in separate processes (True) or as threads of this process
        (False: starts in a fraction of a second; the toolkit's heavy code,
        torch, numpy and the compiled descriptor, releases the GIL).
    **kwargs
        Other ``LocalCluster`` arguments. The dashboard listens on a free port
        unless ``dashboard_address`` is given (Dask's default, 8787, warns
        when another cluster holds it).

    Yields
    ------
    distributed.Client
        The client, also the default client inside the block (so
        ``joblib.parallel_backend("dask")`` uses this cluster).

    Examples
    --------
    >>> import joblib
    >>> from sklearn.linear_model import LogisticRegression
    >>> from sklearn.model_selection import cross_val_score
    >>> from skgesture.parallel import local_cluster
    >>> X, y = [[0.0], [1.0], [2.0], [3.0]] * 5, [0, 0, 1, 1] * 5
    >>> with local_cluster() as client, joblib.parallel_backend("dask"):
    ...     scores = cross_val_score(LogisticRegression(), X, y, cv=2)
    >>> scores.tolist()
    [1.0, 1.0]
    """
    try:
        from distributed import Client, LocalCluster
    except ImportError as exc:
        raise ImportError(f"local_cluster needs Dask; {_DASK_HINT}") from exc
    kwargs.setdefault("dashboard_address", ":0")
    cluster = LocalCluster(
        n_workers=n_workers,
        threads_per_worker=threads_per_worker,
        processes=processes,
        **kwargs,
    )
    client = None
    try:
        client = Client(cluster)
        yield client
    finally:
        close_cluster(cluster, client)
