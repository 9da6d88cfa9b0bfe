"""Live skeleton sources over loopback: UDP datagrams on 127.0.0.1, CSV rows on
a text stream, a Lab Streaming Layer outlet and inlet in this process. Each
drives a StreamingRecognizer frame by frame, and the events must equal those of
the replay of the same frames; timestamp gaps, out-of-order frames and bad
input are checked against the rule of ``skgesture/streaming/_sources.py``."""

# SPDX-License-Identifier: BSD-3-Clause

import io
import json
import os
import socket
import threading
import uuid
import warnings

import numpy as np
import pytest
from _stand_ins import make_cheap_pipeline

from skgesture.datasets import load_precog
from skgesture.streaming import (
    LSLSource,
    ReplaySource,
    SkeletonSource,
    StdinSource,
    StreamingRecognizer,
    UDPSource,
)
from skgesture.streaming._sources import MAX_GAP_SECONDS, _FrameClock

FPS = 30.0
N_FRAMES = 400
SOCKET_TIMEOUT = 5.0  # seconds; every socket and every stream ends by itself


@pytest.fixture(scope="module")
def precog():
    return load_precog()


@pytest.fixture(scope="module")
def pipe(precog):
    """Always-active segmenter and a numpy window classifier (fast)."""
    idx = [i for i, g in enumerate(precog.groups) if g == 1]
    pipe = make_cheap_pipeline()
    return pipe.fit([precog.X[i] for i in idx], [precog.y[i] for i in idx])


@pytest.fixture(scope="module")
def frames(precog):
    """The first 400 frames of a PRECOG recording of subject 8 (Kinect v1)."""
    i = next(i for i, g in enumerate(precog.groups) if g == 8)
    return np.asarray(precog.X[i][:N_FRAMES], dtype=np.float64)


@pytest.fixture(scope="module")
def replayed(pipe, frames):
    events = StreamingRecognizer(pipe).recognize(frames)
    assert events, "the test stream must give events"
    return events


def _live(pipe, source):
    """Push every frame of a source, one by one; the frames and the events."""
    rec = StreamingRecognizer(pipe)
    seen, events = [], []
    for frame in source:
        seen.append(frame)
        events += rec.push(frame)
    return np.array(seen), events + rec.flush()


def _sender():
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sock.settimeout(SOCKET_TIMEOUT)
    return sock


def _datagram(t, joints=None, **extra):
    message = {"t": t, **extra}
    if joints is not None:
        message["joints"] = np.asarray(joints).tolist()
    return json.dumps(message).encode()


def _read_udp(datagrams, **params):
    """Send datagrams (all at once: a few only), then read them as frames."""
    with UDPSource(port=0, fps=FPS, timeout=0.5, **params) as source:
        with _sender() as sock:
            for data in datagrams:
                sock.sendto(data, source.bound_address)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            got = list(source)
    return source, np.array(got), [str(w.message) for w in caught]


# -- the rule --------------------------------------------------------------------


@pytest.mark.parametrize(
    "periods, fill",
    [(1, 0), (1.4, 0), (1.6, 1), (2, 1), (3.49, 2), (0.3, 0), (7, 6)],
)
def test_a_frame_k_periods_later_follows_k_minus_1_untracked_frames(periods, fill):
    clock = _FrameClock(fps=FPS)
    assert clock.gap(100.0) == (0, 0)
    assert clock.gap(100.0 + periods / FPS) == (fill, 0)


def test_the_fill_is_capped_and_out_of_order_frames_are_dropped():
    clock = _FrameClock(fps=10.0)
    assert clock.gap(0.0) == (0, 0)
    cap = int(MAX_GAP_SECONDS * 10)
    assert clock.gap(20.0) == (cap, 199 - cap)
    assert clock.gap(20.0) is None  # duplicate
    assert clock.gap(19.9) is None  # out of order
    assert clock.gap(20.1) == (0, 0)  # the previous accepted frame counts


# -- UDP ---------------------------------------------------------------------------


def test_udp_stream_gives_the_events_of_replay(pipe, frames, replayed):
    """A sender thread streams the recording over a real UDP socket on
    127.0.0.1; the receiver pushes each frame as it comes. Flow control: at
    most 32 datagrams are in flight (the receiver's acknowledgement is a
    semaphore), so loopback cannot drop any under load."""
    window = threading.Semaphore(32)
    stop = threading.Event()
    source = UDPSource(port=0, fps=FPS, timeout=SOCKET_TIMEOUT, max_frames=N_FRAMES)
    assert source.bound_address[0] == "127.0.0.1" and source.bound_address[1] > 0

    def send():
        with _sender() as sock:
            for i, frame in enumerate(frames):
                while not window.acquire(timeout=0.1):
                    if stop.is_set():
                        return
                sock.sendto(_datagram(i / FPS, frame), source.bound_address)

    def acked(source):
        for frame in source:
            yield frame
            window.release()

    thread = threading.Thread(target=send, daemon=True)
    thread.start()
    try:
        with source:
            seen, events = _live(pipe, acked(source))
    finally:
        stop.set()
        thread.join(SOCKET_TIMEOUT)
    assert not thread.is_alive()
    assert (source.n_dropped_, source.n_filled_, source.n_out_of_order_) == (0, 0, 0)
    np.testing.assert_array_equal(seen, frames)  # JSON floats round-trip exactly
    assert events == replayed


def test_udp_gaps_become_untracked_frames_in_place(frames):
    stamps = [0, 1, 2, 5, 6, 6.4, 9]  # in nominal periods
    datagrams = [_datagram(k / FPS, frames[i]) for i, k in enumerate(stamps)]
    source, got, messages = _read_udp(datagrams)
    tracked = got.any(axis=(1, 2))
    # 6.4 is early (0.4 periods: no gap), 9 is 2.6 periods after it (round: 3).
    assert tracked.tolist() == [1, 1, 1, 0, 0, 1, 1, 1, 0, 0, 1]
    np.testing.assert_array_equal(got[tracked], frames[: len(stamps)])
    assert (source.n_filled_, source.n_frames_, messages) == (4, 11, [])


def test_udp_drops_out_of_order_and_duplicate_frames_with_a_warning(frames):
    stamps = [0, 1, 2, 1.5, 2, 3]
    datagrams = [_datagram(k / FPS, frames[i]) for i, k in enumerate(stamps)]
    source, got, messages = _read_udp(datagrams)
    np.testing.assert_array_equal(got, frames[[0, 1, 2, 5]])
    assert source.n_out_of_order_ == 2 and source.n_filled_ == 0
    assert len(messages) == 2
    assert all("out of order or a duplicate" in m for m in messages)


def test_udp_caps_a_long_gap_with_a_clear_warning(frames):
    datagrams = [_datagram(0.0, frames[0]), _datagram(60.0, frames[1])]
    source, got, messages = _read_udp(datagrams)
    cap = int(MAX_GAP_SECONDS * FPS)
    assert len(got) == cap + 2 and source.n_filled_ == cap
    assert not got[1:-1].any()
    assert len(messages) == 1 and "a gap of 60.000 s" in messages[0]
    assert f"{cap} untracked frames" in messages[0]


def test_udp_skips_malformed_datagrams_says_why_and_goes_on(frames):
    good = frames[0]
    nan = good.copy()
    nan[3, 1] = np.nan
    bad = [
        (b"{not json", "not JSON"),
        (b"\xff\xfe\x00", "not JSON"),
        (b"[" * 60_000, "not JSON"),  # too deep to parse
        (b"[1, 2]", "JSON list, not an object"),
        (_datagram(None, good), '"t" is None'),
        (_datagram("0.1", good), "not a finite number"),
        (_datagram(True, good), '"t" is True'),
        (json.dumps({"t": 10**400, "joints": good.tolist()}).encode(), '"t" is 1000'),
        (_datagram(0.1), 'no "joints"'),
        (_datagram(0.1, good[:19]), "shape (19, 3)"),
        (_datagram(0.1, good[:, :2]), "shape (20, 2)"),
        (_datagram(0.1, good.ravel()[:59]), "shape (59,)"),
        (_datagram(0.1, [[0, 1, "a"]] * 20), "not 20 [x, y, z] lists"),
        (_datagram(0.1, nan), "joint 3 holds"),
        (_datagram(0.1, good * 1e6), "beyond 100000"),
        (_datagram(0.1, good, tracked="no"), "\"tracked\" is 'no'"),
    ]
    datagrams = [_datagram(0.0, good)]
    datagrams += [data for data, _ in bad]
    datagrams += [_datagram(1 / FPS, good.ravel()), _datagram(2 / FPS, tracked=False)]
    datagrams += [_datagram(3 / FPS, np.c_[good, np.ones(20)])]  # confidences
    source, got, messages = _read_udp(datagrams)
    assert source.n_dropped_ == len(bad)
    assert len(got) == 4 and source.n_filled_ == 0
    np.testing.assert_array_equal(got[[0, 1, 3]], [good] * 3)
    assert not got[2].any()  # "tracked": false
    # At most 10 warnings of one kind; the rest are counted only.
    assert len(messages) == 10 and "further ones are only counted" in messages[-1]
    for message, (_, why) in zip(messages, bad):
        assert why in message, (why, message)


def test_udp_maps_other_layouts_and_stops_on_timeout_and_close():
    frame = np.zeros((25, 3))
    frame[:, 2] = 2.0
    source, got, _ = _read_udp([_datagram(0.0, frame)], layout="kinect_v2")
    assert got.shape == (1, 20, 3) and (got[0, :, 2] == 2.0).all()
    source = UDPSource(port=0, timeout=0.2)
    assert list(source) == []
    source.close()
    assert list(source) == []
    with pytest.raises(ValueError, match="unknown layout"):
        UDPSource(port=0, layout="kinect3")
    with pytest.raises(ValueError, match="timeout must be a positive"):
        UDPSource(port=0, timeout=0)
    with UDPSource(port=0) as taken, pytest.raises(OSError, match="cannot listen"):
        UDPSource(port=taken.bound_address[1])


def test_close_from_another_thread_ends_a_blocked_stream():
    source = UDPSource(port=0)  # no timeout: only close() ends it
    timer = threading.Timer(0.3, source.close)
    timer.start()
    assert list(source) == []
    timer.join()


# -- stdin (CSV rows) ---------------------------------------------------------


def _csv(rows):
    return "\n".join(",".join(repr(float(v)) for v in row) for row in rows) + "\n"


@pytest.mark.parametrize("with_t", [False, True])
def test_stdin_rows_give_the_events_of_replay(pipe, frames, replayed, with_t):
    rows = frames.reshape(len(frames), -1)
    if with_t:
        rows = np.c_[np.arange(len(frames)) / FPS + 0.5, rows]
    text = "# a live pipe\n\n" + _csv(rows[:10]) + "   # comment\n" + _csv(rows[10:])
    source = StdinSource(io.StringIO(text), fps=FPS)
    seen, events = _live(pipe, source)
    assert source.timestamps_ is with_t
    np.testing.assert_array_equal(seen, frames)
    assert events == replayed


def test_stdin_reads_sys_stdin_by_default(monkeypatch, frames):
    monkeypatch.setattr("sys.stdin", io.StringIO(_csv(frames[:3].reshape(3, -1))))
    np.testing.assert_array_equal(list(StdinSource()), frames[:3])


def test_stdin_timestamp_gaps_and_whitespace_rows(frames):
    rows = np.c_[np.array([0, 1, 4, 4, 5]) / FPS, frames[:5].reshape(5, -1)]
    text = "t x y z ...\n" + "\n".join(" ".join(map(repr, r)) for r in rows.tolist())
    source = StdinSource(io.StringIO(text), fps=FPS)
    with pytest.warns(UserWarning, match="line 5: .*out of order or a duplicate"):
        got = np.array(list(source))
    assert got.any(axis=(1, 2)).tolist() == [1, 1, 0, 0, 1, 1]
    assert (source.n_filled_, source.n_out_of_order_) == (2, 1)


def test_stdin_a_frame_counter_column_is_ambiguous(frames):
    rows = np.c_[np.arange(3), frames[:3].reshape(3, -1)]
    with pytest.raises(ValueError, match="lines 1 and 2 .* timestamps=True"):
        list(StdinSource(io.StringIO(_csv(rows))))
    source = StdinSource(io.StringIO(_csv(rows)), fps=1.0, timestamps=True)
    assert len(list(source)) == 3 and source.n_filled_ == 0


def test_stdin_a_first_row_of_no_known_count_names_the_line():
    text = "# comment\n" + ",".join(["1"] * 75) + "\n"
    with pytest.raises(ValueError, match="line 2 has 75 values.*expected 60 .* or 61"):
        list(StdinSource(io.StringIO(text)))
    assert len(list(StdinSource(io.StringIO(text), layout="kinect_v2"))) == 1


def test_stdin_bad_lines_are_skipped_with_their_line_number(frames):
    rows = frames[:6].reshape(6, -1).tolist()
    lines = [",".join(map(repr, r)) for r in rows]
    lines[2] = lines[2].replace(repr(rows[2][5]), "abc")
    lines[3] = ",".join(lines[3].split(",")[:50])
    lines[4] = lines[4].replace(repr(rows[4][0]), "inf")
    source = StdinSource(io.StringIO("\n".join(lines)), timestamps=False)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        got = np.array(list(source))
    messages = [str(w.message) for w in caught]
    assert len(messages) == 3 and source.n_dropped_ == 3
    whys = ["line 3: 'abc'", "line 4: 50 values", "line 5: joint 0"]
    for message, why in zip(messages, whys):
        assert why in message
    # A skipped row keeps its frame period, as an untracked frame.
    assert got.any(axis=(1, 2)).tolist() == [1, 1, 0, 0, 0, 1]
    np.testing.assert_array_equal(got[[0, 1, 5]], frames[[0, 1, 5]])


def test_stdin_nan_rows_are_untracked_frames(frames):
    rows = frames[:3].reshape(3, -1).copy()
    rows[1, 7] = np.nan
    got = np.array(list(StdinSource(io.StringIO(_csv(rows)))))
    assert got.any(axis=(1, 2)).tolist() == [1, 0, 1]


# -- Lab Streaming Layer ----------------------------------------------------------


@pytest.fixture(scope="module")
def pylsl(tmp_path_factory):
    """pylsl with LSL discovery kept on this machine (loopback only)."""
    config = tmp_path_factory.mktemp("lsl") / "lsl_api.cfg"
    config.write_text("[ports]\nIPv6 = disable\n[multicast]\nResolveScope = machine\n")
    old = os.environ.get("LSLAPICFG")
    os.environ["LSLAPICFG"] = str(config)
    try:
        import pylsl

        pylsl.library_version()
    except Exception as exc:  # ImportError, or RuntimeError without liblsl
        pytest.skip(f"pylsl or liblsl cannot load here ({type(exc).__name__}: {exc})")
    yield pylsl
    if old is None:
        os.environ.pop("LSLAPICFG", None)
    else:
        os.environ["LSLAPICFG"] = old


def _outlet(pylsl, n_channels=60, fps=FPS):
    name = f"skgesture-test-{uuid.uuid4().hex[:8]}"
    info = pylsl.StreamInfo(name, "Mocap", n_channels, fps, pylsl.cf_double64, name)
    return name, pylsl.StreamOutlet(info)


def test_lsl_stream_gives_the_events_of_replay(pylsl, pipe, frames, replayed):
    name, outlet = _outlet(pylsl)
    source = LSLSource(name, timeout=SOCKET_TIMEOUT, max_frames=N_FRAMES)
    assert source.fps == FPS
    t0 = pylsl.local_clock()
    for i, frame in enumerate(frames):
        outlet.push_sample(frame.ravel().tolist(), t0 + i / FPS)
    with source:
        seen, events = _live(pipe, source)
    assert (source.n_dropped_, source.n_filled_, source.n_out_of_order_) == (0, 0, 0)
    np.testing.assert_array_equal(seen, frames)
    assert events == replayed
    del outlet


def test_lsl_gaps_out_of_order_and_bad_samples(pylsl, frames):
    name, outlet = _outlet(pylsl)
    source = LSLSource(name, timeout=0.5)
    untracked = np.full(60, np.nan)
    samples = [
        (0, frames[0].ravel()),
        (3, frames[1].ravel()),  # two frames lost
        (2, frames[2].ravel()),  # out of order
        (4, untracked),  # nobody tracked
        (5, np.full(60, np.inf)),  # bad: skipped, counted
        (6, frames[3].ravel()),
    ]
    t0 = pylsl.local_clock()
    for k, sample in samples:
        outlet.push_sample(sample.tolist(), t0 + k / FPS)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        with source:
            got = np.array(list(source))
    assert got.any(axis=(1, 2)).tolist() == [1, 0, 0, 1, 0, 0, 1]
    assert (source.n_filled_, source.n_out_of_order_, source.n_dropped_) == (3, 1, 1)
    assert len(caught) == 2
    del outlet


def test_lsl_refuses_a_stream_it_cannot_read(pylsl):
    name, outlet = _outlet(pylsl, n_channels=61)
    with pytest.raises(ValueError, match="61 channels.*expected 60"):
        LSLSource(name)
    with pytest.raises(LookupError, match="no LSL stream named 'nope"):
        LSLSource(f"nope-{uuid.uuid4().hex[:8]}", resolve_timeout=0.2)
    del outlet


def test_lsl_without_pylsl_names_the_extra(monkeypatch):
    import builtins

    real_import = builtins.__import__

    def no_pylsl(name, *args, **kwargs):
        if name == "pylsl":
            raise ImportError("No module named 'pylsl'")
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", no_pylsl)
    with pytest.raises(ImportError, match=r"skgesture\[lsl\]"):
        LSLSource("kinect")


def test_every_source_is_a_skeleton_source():
    for cls in (UDPSource, StdinSource, LSLSource, ReplaySource):
        assert issubclass(cls, SkeletonSource)
