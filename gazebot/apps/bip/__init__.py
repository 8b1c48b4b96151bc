"""The seed's chapter 7.4-7.5: Bayesian Interaction Primitives (BIPs) for the two-handed reach of a
robot giver, and the two ways of 7.5 to keep its hands at the object's grip width.

- :mod:`~gazebot.apps.bip.basis`: Gaussian radial basis functions on the phase, ridge weights.
- :mod:`~gazebot.apps.bip.demos`: the two-handed handover demonstrations (generator, files).
- :mod:`~gazebot.apps.bip.prior`: the BIP prior over weights, phase and phase velocity.
- :mod:`~gazebot.apps.bip.constraint`: the grip-width constraint as a linear equality, the
  KL-minimal projection of a Gaussian onto it and of an ensemble onto it.
- :mod:`~gazebot.apps.bip.enbip`: the ensemble BIP filter (Campbell et al.).
- :mod:`~gazebot.apps.bip.evaluate`: prediction errors on held-out demonstrations.
- :mod:`~gazebot.apps.bip.scene`: a kinematic robot-giver scene with the gaze engine in the loop.

See ``docs/seed/bip.md``.
"""
