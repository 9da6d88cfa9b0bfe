"""Framewise taggers: they label every frame of a sequence.

* ``_base``: what every tagger shares (label encoding, checks, caching, decoding);
* ``_sequence``: :class:`~skgesture.SequenceTagger` (the recommended model);
* ``_voting``: :class:`~skgesture.VotingTagger`;
* ``_bilstm``: :class:`~skgesture.BiLSTMTagger` (Method C);
* ``_decoding``: the one decoding path, offline and live (``LabelRuns``);
* ``_stream``: the taggers' live steps.

Nothing is imported here: users import the taggers from :mod:`skgesture`.
"""

# SPDX-License-Identifier: BSD-3-Clause
