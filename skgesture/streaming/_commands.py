"""A command vocabulary for any model, its state machine, and command publishers.

:class:`CommandMap` says which command each gesture class gives, for any number
of classes and any commands, and optionally which commands are valid in which
state and where each leads (a small JSON or TOML file, docs/streaming.md,
"Command files"). It is checked on its own when it is built and against a
model's classes when it is bound to one. :class:`CommandEvent` is one published
command; :class:`JSONLinesPublisher` and :class:`UDPPublisher` send them as
JSON objects, one per line or one per datagram. The wiring (recogniser, action
map, robot, publishers) is :class:`~skgesture.streaming.GestureCommander`.
"""

# SPDX-License-Identifier: BSD-3-Clause

import json
import socket
import sys
import time
from collections.abc import Mapping
from dataclasses import dataclass
from numbers import Integral
from pathlib import Path

__all__ = ["CommandMap", "CommandEvent", "JSONLinesPublisher", "UDPPublisher"]

_FILE_KEYS = ("commands", "states", "initial", "arming")
_ARMING_KEYS = ("class", "frames", "disarm_on_command")
_ARMING_AT = "arming[%r]"  # an entry of the arming table, in messages
DEFAULT_ARMING_FRAMES = 90  # 3 s at 30 fps: the window after an arming gesture
MAX_DATAGRAM = 65_507  # the largest UDP payload over IPv4


def _class_key(key, where):
    """A ``commands`` key as a class number (int >= 1) or a class name (str)."""
    if isinstance(key, str):
        text = key.strip()
        if not text:
            raise ValueError(f"{where}: a gesture class cannot be an empty string")
        if text.isdecimal():  # "3" in a JSON or TOML file is class number 3
            key = int(text)
        else:
            return text
    if isinstance(key, bool) or not isinstance(key, Integral):
        raise ValueError(
            f"{where}: a gesture class is a class number (int >= 1) or a class "
            f"name (str), got {key!r} of type {type(key).__name__}"
        )
    if key < 1:
        raise ValueError(
            f"{where}: class {key} cannot give a command: class numbers start at 1 "
            f"(0 is rest)"
        )
    return int(key)


def _command(value, where):
    if not isinstance(value, str) or not value.strip():
        raise ValueError(
            f"{where}: a command must be a non-empty string, got {value!r}"
        )
    return value.strip()


def _describe_classes(classes, target_names):
    if target_names is None:
        return ", ".join(map(str, classes))
    return ", ".join(
        f"{c} {target_names[c - 1]!r}" if c <= len(target_names) else str(c)
        for c in classes
    )


def resolve_classes(entries, classes, target_names=None, where=None):
    """``{label: command}`` from ``{class number or name: command}``, checked.

    Parameters
    ----------
    entries : iterable of tuple
        ``(shown key, class number or name, command)``.
    classes : array-like of int
        The model's gesture classes (0, rest, is dropped).
    target_names : sequence of str or None
        ``target_names[k - 1]`` names class ``k``.
    where : callable
        ``where(shown key)`` is the prefix of an error message.

    Returns
    -------
    dict
        ``{label: command}``.
    """
    where = where or (lambda key: f"mapping[{key!r}]")
    classes = sorted({int(c) for c in classes} - {0})
    names = None if target_names is None else list(target_names)
    known = _describe_classes(classes, names)
    out, given_as = {}, {}
    for shown, key, command in entries:
        if isinstance(key, str):
            if names is None:
                raise ValueError(
                    f"{where(shown)}: {key!r} is a class name, but the model has no "
                    f"class names (target_names); give its class number ({known})"
                )
            if key not in names:
                raise ValueError(
                    f"{where(shown)}: unknown class name {key!r}; the model's classes "
                    f"are {known}"
                )
            label = names.index(key) + 1
        else:
            label = key
        if label not in classes:
            raise ValueError(
                f"{where(shown)}: class {label} is not a class of the model (its "
                f"classes are {known})"
            )
        if label in out:
            raise ValueError(
                f"{where(shown)}: class {label} is given twice, as {given_as[label]!r} "
                f"and as {shown!r}; give one command per class"
            )
        out[label], given_as[label] = command, shown
    return out


class CommandMap:
    """Gesture classes to commands, with an optional state machine.

    The vocabulary of a gesture interface: any number of gesture classes, each
    given by its class number or its class name, each giving a command (a
    string: it is published as JSON); several classes may give the same
    command. With ``states``, a command is valid only in the states that list
    it, and leads to the state it names there; the
    :class:`~skgesture.streaming.GestureCommander` rejects (does not publish)
    a command that is not valid in its current state.

    The map is checked twice. When it is built: an empty mapping, a command
    that is not a non-empty string, a class number below 1, the same class
    written twice, an unknown ``initial`` state, a transition to a state that
    is not defined, a state listing a command that no gesture gives, and a
    command valid in no state are errors. When it is bound to a model
    (:meth:`bind`, done by ``GestureCommander``): a class name that is not in
    the model's ``target_names``, a class number that is not among its
    classes, and a class given twice (by name and by number) are errors. Every
    error is a ValueError that names the entry, and the file when the map was
    read from one.

    Why a class apart from :class:`~skgesture.streaming.ActionMap`: the map is
    data (a file written once per robot or program, checked against each
    model it is used with), while an ``ActionMap`` is the per-event policy of
    one stream (confidence floor, refractory period, the last command's
    frame). ``ActionMap(command_map, min_confidence=...)`` takes one, and
    keeps working with a plain ``{class: command}`` dict as before.

    Parameters
    ----------
    commands : dict
        ``{gesture class: command}``. A class is a class number (an int >= 1,
        or a string of digits such as ``"3"``, as in a JSON or TOML file) or a
        class name (any other string).
    states : dict or None, default=None
        ``{state: {command: next state}}``: the commands valid in each state
        and the state each leads to. None: every command is always valid.
    initial : str or None, default=None
        The state a stream starts in; required with ``states``.
    arming : dict or None, default=None
        The arming gesture (see :class:`~skgesture.streaming.ActionMap`):
        ``{"class": gesture class, "frames": 90, "disarm_on_command": True}``,
        ``class`` required; a command is then accepted only within ``frames``
        frames after that gesture. The arming class gives no command, so it
        must not be a key of ``commands``. None: no arming gesture.
    source : str or None, default=None
        Where the map comes from (a file name), for error messages.

    Attributes
    ----------
    commands : dict
        The entries as given (``{class number or name: command}``).
    states : dict or None
        The state machine as given.
    initial : str or None
        The initial state.
    arming : dict or None
        ``{"class", "frames", "disarm_on_command"}``, checked and completed
        with the defaults, or None.
    mapping : dict or None
        ``{label: command}`` once bound (:meth:`bind`), else None.
    arming_label : int or None
        The arming gesture's label once bound, else None.
    classes : tuple of int or None
        The model's classes once bound, else None.

    See Also
    --------
    ActionMap : Confidence floor and refractory period on top of a map.
    GestureCommander : Recogniser, map, state machine, robot and publishers.

    Notes
    -----
    The file (``.json`` or ``.toml``, docs/streaming.md, "Command files")::

        {
          "commands": {"wave": "stop", "3": "pick", "point_left": "move_left"},
          "states": {"idle": {"pick": "holding", "move_left": "idle",
                              "stop": "idle"},
                     "holding": {"place": "idle", "stop": "holding"}},
          "initial": "idle"
        }

    An optional fourth key, ``"arming": {"class": "raise_hand", "frames":
    90}``, names the arming gesture. Only these keys are read; any other key
    is an error (a misspelt ``"comands"`` would otherwise silently give no
    commands). In TOML, the same tables: ``initial = "idle"``, ``[commands]``
    with ``wave = "stop"`` and ``3 = "pick"``, ``[states.idle]`` with ``pick =
    "holding"``, ``[arming]`` with ``class = "raise_hand"``.

    Examples
    --------
    >>> from skgesture.streaming import CommandMap
    >>> cmap = CommandMap(
    ...     {"wave": "stop", 3: "pick", "2": "place"},
    ...     states={"idle": {"pick": "holding", "stop": "idle"},
    ...             "holding": {"place": "idle", "stop": "holding"}},
    ...     initial="idle")
    >>> cmap.allowed("idle")
    ['stop', 'pick']
    >>> cmap.next_state("holding", "place")
    'idle'
    >>> bound = cmap.bind([1, 2, 3], target_names=["wave", "push", "grab"])
    >>> bound.mapping
    {1: 'stop', 3: 'pick', 2: 'place'}
    >>> cmap.bind([1, 2])
    Traceback (most recent call last):
    ...
    ValueError: commands['wave']: 'wave' is a class name, but the model has no \
class names (target_names); give its class number (1, 2)
    """

    def __init__(
        self, commands, *, states=None, initial=None, arming=None, source=None
    ):
        self.source = None if source is None else str(source)
        if not isinstance(commands, Mapping):
            raise ValueError(
                f"{self._at('commands')}must be a table {{gesture class: command}}, "
                f"got {type(commands).__name__}"
            )
        if not commands:
            raise ValueError(
                f"{self._at('commands')}is empty: map at least one gesture class "
                f"to a command"
            )
        self.commands = dict(commands)
        self._entries = []
        seen = {}
        for key, command in self.commands.items():
            where = self._where(key)
            cls = _class_key(key, where)
            if cls in seen:
                raise ValueError(
                    f"{where}: class {cls!r} is given twice (also as "
                    f"{seen[cls]!r}); give one command per class"
                )
            seen[cls] = key
            self._entries.append((key, cls, _command(command, where)))
        self.vocabulary = list(dict.fromkeys(c for _, _, c in self._entries))
        self.states, self.initial = self._check_states(states, initial)
        self.arming = self._check_arming(arming, seen)
        self.mapping = None
        self.classes = None
        self.arming_label = None

    def _at(self, key):
        return f"{self.source}: {key}: " if self.source else f"{key}: "

    def _where(self, key):
        text = f"commands[{key!r}]"
        return f"{self.source}: {text}" if self.source else text

    def _check_states(self, states, initial):
        if states is None:
            if initial is not None:
                raise ValueError(
                    f"{self._at('initial')}{initial!r} is given without states"
                )
            return None, None
        if not isinstance(states, Mapping) or not states:
            raise ValueError(
                f"{self._at('states')}must be a non-empty table {{state: {{command: "
                f"next state}}}}, got {states!r}"
            )
        names = list(states)
        for state in names:
            if not isinstance(state, str) or not state.strip():
                raise ValueError(
                    f"{self._at('states')}a state must be a non-empty string, got "
                    f"{state!r}"
                )
        if initial is None:
            raise ValueError(
                f"{self._at('initial')}missing: name the state a stream starts in "
                f"(one of {', '.join(names)})"
            )
        if initial not in states:
            raise ValueError(
                f"{self._at('initial')}{initial!r} is not a state (states: "
                f"{', '.join(names)})"
            )
        checked = {}
        for state, moves in states.items():
            where = f"states[{state!r}]"
            if not isinstance(moves, Mapping):
                raise ValueError(
                    f"{self._at(where)}must be a table {{command: next state}}, got "
                    f"{moves!r}"
                )
            checked[state] = {}
            for command, target in moves.items():
                at = self._at(f"{where}[{command!r}]")
                if command not in self.vocabulary:
                    raise ValueError(
                        f"{at}{command!r} is not a command of the mapping (commands: "
                        f"{', '.join(self.vocabulary)})"
                    )
                if target not in states:
                    raise ValueError(
                        f"{at}leads to {target!r}, which is not a state (states: "
                        f"{', '.join(names)})"
                    )
                checked[state][command] = target
        used = {c for moves in checked.values() for c in moves}
        for key, _, command in self._entries:
            if command not in used:
                raise ValueError(
                    f"{self._where(key)}: command {command!r} is valid in no state; "
                    f"list it under the states where it may be given"
                )
        return checked, initial

    def _check_arming(self, arming, seen):
        """The ``arming`` table, checked and completed with the defaults."""
        if arming is None:
            return None
        if not isinstance(arming, Mapping):
            raise ValueError(
                f'{self._at("arming")}must be a table {{"class": gesture class, '
                f'"frames": int}}, got {arming!r}'
            )
        unknown = [k for k in arming if k not in _ARMING_KEYS]
        if unknown:
            raise ValueError(
                f"{self._at('arming')}unknown key(s) {', '.join(map(repr, unknown))}; "
                f"the arming table has {', '.join(map(repr, _ARMING_KEYS))}"
            )
        if "class" not in arming:
            raise ValueError(
                f"{self._at('arming')}no 'class': name the arming gesture (a class "
                f"number or name)"
            )
        where = self._at(_ARMING_AT % "class").rstrip(": ")
        cls = _class_key(arming["class"], where)
        if cls in seen:
            raise ValueError(
                f"{where}: class {cls!r} is the arming gesture and also gives a "
                f"command (commands[{seen[cls]!r}]); the arming gesture gives no "
                f"command"
            )
        frames = arming.get("frames", DEFAULT_ARMING_FRAMES)
        if isinstance(frames, bool) or not isinstance(frames, Integral) or frames < 1:
            raise ValueError(
                f"{self._at(_ARMING_AT % 'frames')}must be a positive int (frames "
                f"after the arming gesture), got {frames!r}"
            )
        disarm = arming.get("disarm_on_command", True)
        if not isinstance(disarm, bool):
            raise ValueError(
                f"{self._at(_ARMING_AT % 'disarm_on_command')}must be true or "
                f"false, got {disarm!r}"
            )
        return {"class": cls, "frames": int(frames), "disarm_on_command": disarm}

    @classmethod
    def from_dict(cls, data, *, source=None):
        """A map from ``{"commands": ..., "states": ..., "initial": ...}``.

        Parameters
        ----------
        data : dict
            The contents of a command file; ``states``, ``initial`` and
            ``arming`` are optional, any other key is an error.
        source : str or None, default=None
            Where it comes from, for error messages.

        Returns
        -------
        CommandMap
            Not yet bound to a model.

        Examples
        --------
        >>> from skgesture.streaming import CommandMap
        >>> CommandMap.from_dict({"commands": {"1": "beep"}}).commands
        {'1': 'beep'}
        """
        prefix = f"{source}: " if source else ""
        if not isinstance(data, Mapping):
            raise ValueError(
                f"{prefix}a command file holds a table with 'commands' (and "
                f"optionally 'states', 'initial' and 'arming'), got "
                f"{type(data).__name__}"
            )
        unknown = [k for k in data if k not in _FILE_KEYS]
        if unknown:
            raise ValueError(
                f"{prefix}unknown key(s) {', '.join(map(repr, unknown))}; a command "
                f"file has {', '.join(map(repr, _FILE_KEYS))}"
            )
        if "commands" not in data:
            raise ValueError(f"{prefix}no 'commands' table {{gesture class: command}}")
        return cls(
            data["commands"],
            states=data.get("states"),
            initial=data.get("initial"),
            arming=data.get("arming"),
            source=source,
        )

    @classmethod
    def from_file(cls, path):
        """Read a map from a ``.json`` or ``.toml`` file.

        Parameters
        ----------
        path : str or path-like
            The file (format in the class's Notes and in docs/streaming.md,
            "Command files").

        Returns
        -------
        CommandMap
            Not yet bound to a model.

        Examples
        --------
        >>> import json, pathlib, tempfile
        >>> from skgesture.streaming import CommandMap
        >>> path = pathlib.Path(tempfile.mkdtemp()) / "commands.json"
        >>> _ = path.write_text(json.dumps({"commands": {"1": "go", "2": "stop"}}))
        >>> CommandMap.from_file(path).vocabulary
        ['go', 'stop']
        """
        path = Path(path)
        suffix = path.suffix.lower()
        if suffix == ".json":
            try:
                data = json.loads(
                    path.read_text(encoding="utf-8"), object_pairs_hook=_no_duplicates
                )
            except json.JSONDecodeError as exc:
                raise ValueError(f"{path}: not valid JSON: {exc}") from None
            except _DuplicateKey as exc:
                raise ValueError(f"{path}: {exc}") from None
        elif suffix == ".toml":
            toml = _toml(path)
            try:
                data = toml.loads(path.read_text(encoding="utf-8"))
            except toml.TOMLDecodeError as exc:
                raise ValueError(f"{path}: not valid TOML: {exc}") from None
        else:
            raise ValueError(
                f"{path}: a command file is .json or .toml, got "
                f"{suffix or 'no suffix'!r}"
            )
        return cls.from_dict(data, source=str(path))

    @property
    def bound(self):
        """Whether the map was bound to a model's classes (:meth:`bind`)."""
        return self.mapping is not None

    def bind(self, classes, target_names=None):
        """Check the map against a model's classes and resolve class names.

        Parameters
        ----------
        classes : array-like of int
            The model's gesture classes (``recognizer.classes_``; 0, rest, is
            ignored).
        target_names : sequence of str or None, default=None
            ``target_names[k - 1]`` names class ``k``; needed for the classes
            given by name.

        Returns
        -------
        CommandMap
            A bound copy, with :attr:`mapping` ``{label: command}``; this map
            is unchanged and can be bound to another model.

        Raises
        ------
        ValueError
            For a class name the model does not have, a class number not
            among its classes, or a class given twice (by name and number);
            the same for the arming gesture, which also must not be a class
            that gives a command.

        Examples
        --------
        >>> from skgesture.streaming import CommandMap
        >>> CommandMap({"4": "go"}).bind([1, 2, 3])
        Traceback (most recent call last):
        ...
        ValueError: commands['4']: class 4 is not a class of the model (its \
classes are 1, 2, 3)
        """
        bound = object.__new__(type(self))
        bound.__dict__.update(self.__dict__)
        bound.mapping = resolve_classes(
            self._entries, classes, target_names, where=self._where
        )
        bound.classes = tuple(sorted({int(c) for c in classes} - {0}))
        if self.arming is not None:
            where = self._at(_ARMING_AT % "class").rstrip(": ")
            key = self.arming["class"]
            label = resolve_classes(
                [(key, key, None)], classes, target_names, where=lambda _: where
            )
            (bound.arming_label,) = label
            if bound.arming_label in bound.mapping:
                raise ValueError(
                    f"{where}: class {bound.arming_label} is the arming gesture "
                    f"and also gives the command "
                    f"{bound.mapping[bound.arming_label]!r}; the arming gesture "
                    f"gives no command"
                )
        return bound

    def allowed(self, state):
        """The commands valid in ``state`` (all of them without a state machine).

        Parameters
        ----------
        state : str or None
            A state of the map (ignored without ``states``).

        Returns
        -------
        list of str
            In the map's order.
        """
        if self.states is None:
            return list(self.vocabulary)
        return [c for c in self.vocabulary if c in self._moves(state)]

    def next_state(self, state, command):
        """The state ``command`` leads to from ``state``, None if it is invalid there.

        Parameters
        ----------
        state : str or None
            Current state (ignored without ``states``).
        command : str
            A command.

        Returns
        -------
        str or None
            The next state; None when ``command`` is not valid in ``state``,
            or when the map has no states (every command is valid then).
        """
        if self.states is None:
            return None
        return self._moves(state).get(str(command))

    def _moves(self, state):
        if state not in self.states:
            raise ValueError(
                f"unknown state {state!r} (states: {', '.join(self.states)})"
            )
        return self.states[state]

    def to_dict(self):
        """The map as the contents of a command file.

        Returns
        -------
        dict
            ``{"commands": ...}``, with ``states``, ``initial`` and
            ``arming`` when set.
        """
        out = {"commands": {str(k): c for k, _, c in self._entries}}
        if self.states is not None:
            out["states"] = {s: dict(m) for s, m in self.states.items()}
            out["initial"] = self.initial
        if self.arming is not None:
            out["arming"] = dict(self.arming)
        return out

    def __repr__(self):
        extra = "" if self.states is None else f", initial={self.initial!r}"
        if self.arming is not None:
            extra += f", arming={self.arming!r}"
        where = f", source={self.source!r}" if self.source else ""
        return f"CommandMap({self.to_dict()['commands']!r}{extra}{where})"


def _toml(path):
    """The TOML reader: tomllib (Python 3.11+), else tomli if installed."""
    try:
        import tomllib
    except ImportError:  # pragma: no cover - Python 3.10
        try:
            import tomli as tomllib
        except ImportError:
            raise ImportError(
                f"{path}: reading a TOML command file needs Python 3.11 or the "
                f"'tomli' package (pip install tomli); a JSON file works everywhere"
            ) from None
    return tomllib


class _DuplicateKey(Exception):
    pass


def _no_duplicates(pairs):
    out = {}
    for key, value in pairs:
        if key in out:
            raise _DuplicateKey(f"key {key!r} appears twice in one table")
        out[key] = value
    return out


@dataclass(frozen=True)
class CommandEvent:
    """One published command: what was commanded, by which gesture, when.

    Parameters
    ----------
    command : str
        The command.
    label : int
        The gesture class that gave it.
    name : str or None
        The class's name (None when the recogniser has no ``target_names``).
    confidence : float
        The event's confidence.
    start, end : int
        The gesture's frames (``end`` exclusive).
    frame : int
        The stream frame at which the gesture was recognised (the event's
        ``emitted_at``).
    time : float or None
        ``frame`` in seconds of the stream (None without an ``fps``).
    timestamp : float
        Wall-clock time of publication (seconds since the Unix epoch).
    state : str or None
        The state the command leads to (None without a state machine).
    previous_state : str or None
        The state it was given in.

    Examples
    --------
    >>> from skgesture.streaming import CommandEvent
    >>> ev = CommandEvent("pick", 3, "grab", 0.92, 10, 50, 62, 3.1, 0.0,
    ...                   "holding", "idle")
    >>> ev.to_json()  # doctest: +NORMALIZE_WHITESPACE
    '{"type": "command", "command": "pick", "label": 3, "name": "grab",
      "confidence": 0.92, "start": 10, "end": 50, "frame": 62, "time": 3.1,
      "timestamp": 0.0, "state": "holding", "previous_state": "idle"}'
    """

    command: str
    label: int
    name: str | None
    confidence: float
    start: int
    end: int
    frame: int
    time: float | None
    timestamp: float
    state: str | None = None
    previous_state: str | None = None

    @classmethod
    def from_gesture(cls, event, command, *, fps=None, state=None, previous=None):
        """The command event of a :class:`~skgesture.streaming.GestureEvent`.

        Parameters
        ----------
        event : GestureEvent
            The recognised gesture.
        command : str
            Its command.
        fps : float or None, default=None
            Frame rate, for :attr:`time`.
        state, previous : str or None, default=None
            State after and before the command.

        Returns
        -------
        CommandEvent
            Stamped with the current wall-clock time.
        """
        frame = int(event.emitted_at)
        return cls(
            command=str(command),
            label=int(event.label),
            name=getattr(event, "name", None),
            confidence=float(event.confidence),
            start=int(event.start),
            end=int(event.end),
            frame=frame,
            time=None if fps is None else frame / fps,
            timestamp=time.time(),
            state=state,
            previous_state=previous,
        )

    def to_dict(self):
        """The message: a JSON-ready dict (docs/streaming.md, "Publishing commands").

        Returns
        -------
        dict
            ``type`` (``"command"``) and every field, in order.
        """
        return {"type": "command", **{k: getattr(self, k) for k in _FIELDS}}

    def to_json(self):
        """The message as one line of JSON.

        Returns
        -------
        str
            No newline; NaN is refused (a published command has a finite
            confidence).
        """
        return json.dumps(self.to_dict(), allow_nan=False)


_FIELDS = tuple(CommandEvent.__dataclass_fields__)


class JSONLinesPublisher:
    """Publish commands as JSON lines on a text stream (stdout by default).

    Each :class:`CommandEvent` is written as one JSON object
    (:meth:`CommandEvent.to_dict`) and a newline, and the stream is flushed,
    so a program reading a pipe gets every command at once.

    Parameters
    ----------
    stream : file-like or None, default=None
        Text stream with ``write``; None writes to ``sys.stdout`` as it is at
        each command.

    Attributes
    ----------
    n_published : int
        Commands written.

    Examples
    --------
    >>> import io
    >>> from skgesture.streaming import CommandEvent, JSONLinesPublisher
    >>> out = io.StringIO()
    >>> publish = JSONLinesPublisher(out)
    >>> publish(CommandEvent("stop", 1, None, 0.8, 0, 20, 31, None, 0.0))
    >>> out.getvalue()[:38]
    '{"type": "command", "command": "stop",'
    """

    def __init__(self, stream=None):
        if stream is not None and not callable(getattr(stream, "write", None)):
            raise TypeError(
                "stream must be a text stream with write(), got "
                f"{type(stream).__name__}"
            )
        self.stream = stream
        self.n_published = 0

    def __call__(self, command_event):
        """Write one command.

        Parameters
        ----------
        command_event : CommandEvent
            The command.
        """
        stream = sys.stdout if self.stream is None else self.stream
        stream.write(command_event.to_json() + "\n")
        if callable(getattr(stream, "flush", None)):
            stream.flush()
        self.n_published += 1


class UDPPublisher:
    """Publish commands as JSON datagrams over UDP (standard library only).

    Each :class:`CommandEvent` is one datagram holding one UTF-8 JSON object
    (:meth:`CommandEvent.to_dict`). UDP does not wait for a receiver and does
    not resend: a datagram sent while nothing listens is lost, which suits a
    controller that acts on the latest command.

    Parameters
    ----------
    host : str, default="127.0.0.1"
        Receiver's host name or address (IPv4 or IPv6).
    port : int, default=9001
        Receiver's port (:class:`~skgesture.streaming.UDPSource` listens on
        9000 by default, so both fit on one machine).

    Attributes
    ----------
    address : tuple
        The resolved address the datagrams go to.
    n_published : int
        Datagrams sent.

    Examples
    --------
    >>> import json, socket
    >>> from skgesture.streaming import CommandEvent, UDPPublisher
    >>> receiver = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    >>> receiver.bind(("127.0.0.1", 0))
    >>> receiver.settimeout(5)
    >>> with UDPPublisher("127.0.0.1", receiver.getsockname()[1]) as publish:
    ...     publish(CommandEvent("stop", 1, None, 0.8, 0, 20, 31, None, 0.0))
    >>> json.loads(receiver.recv(65536))["command"]
    'stop'
    >>> receiver.close()
    """

    def __init__(self, host="127.0.0.1", port=9001):
        if not isinstance(host, str) or not host:
            raise ValueError(f"host must be a host name or address, got {host!r}")
        if isinstance(port, bool) or not isinstance(port, Integral):
            raise ValueError(f"port must be an int in 1..65535, got {port!r}")
        if not 1 <= port <= 65535:
            raise ValueError(f"port must be in 1..65535, got {port}")
        try:
            family, _, _, _, address = socket.getaddrinfo(
                host, int(port), type=socket.SOCK_DGRAM
            )[0]
        except socket.gaierror as exc:
            raise ValueError(f"cannot resolve host {host!r}: {exc}") from None
        self.host, self.port, self.address = host, int(port), address
        self._sock = socket.socket(family, socket.SOCK_DGRAM)
        self.n_published = 0

    def __call__(self, command_event):
        """Send one command.

        Parameters
        ----------
        command_event : CommandEvent
            The command.
        """
        if self._sock is None:
            raise ValueError("the UDPPublisher is closed")
        payload = command_event.to_json().encode("utf-8")
        if len(payload) > MAX_DATAGRAM:
            raise ValueError(
                f"a command message of {len(payload)} bytes does not fit in a UDP "
                f"datagram ({MAX_DATAGRAM} bytes)"
            )
        self._sock.sendto(payload, self.address)
        self.n_published += 1

    def close(self):
        """Close the socket (further commands raise)."""
        if self._sock is not None:
            self._sock.close()
            self._sock = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
