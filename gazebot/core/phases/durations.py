"""Typical handover phase durations, one place for every model that needs them.

The phase stream the engine reports is the giver's (the detector follows the giver's hand), so
one set of durations serves the detector's end-of-phase prediction
(:mod:`gazebot.core.phases.prediction`) and the behaviors' fallback when no online estimate exists
(:class:`gazebot.core.behaviors.spec.PhaseDurations`):

- reach 1.01 s: the seed's figure 6.1, giver's hand, 8.10 frames at 8 fps (our count of the
  published annotations: 7.89 frames, 0.99 s; the receivers' own reach is shorter, 6.43
  frames, 0.80 s, but the reach the engine reports is the giver's);
- transfer 0.59 s and retreat 1.05 s: means over the 288 annotated handovers (4.68 and 8.40
  frames at 8 fps; the giver's and the receiver's columns agree).
"""

from __future__ import annotations

#: Typical giver reach (s).
REACH_S = 1.01
#: Typical transfer (s).
TRANSFER_S = 0.59
#: Typical retreat (s).
RETREAT_S = 1.05
