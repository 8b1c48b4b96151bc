"""The ``gazebot`` method's rules, one per phase boundary, each a pure function of the smoothed
:class:`~gazebot.core.phases.filtering.Signals` and the
:class:`~gazebot.core.phases.config.PhaseConfig`:

- :mod:`.transfer`: where handovers are (dips of the hands' distance) and when the transfer
  starts (reach -> transfer);
- :mod:`.release`: when the giver lets go (transfer -> retreat);
- :mod:`.reach`: when the giver's reach starts (idle -> reach);
- :mod:`.retreat`: when the retreat ends (retreat -> done).
"""
