"""The seed's chapter 5: Guided Policy Search with BADMM (section 5.2.1) learning the robot's reach
towards a person's hand, in a MuJoCo scene with a Panda learner and a 2-DoF tester (section 5.4).

Entry points: :func:`gazebot.apps.gps.badmm.train` and :func:`gazebot.apps.gps.evaluate.evaluate`.
"""
