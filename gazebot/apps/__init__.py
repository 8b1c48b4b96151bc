"""gazebot's applications: the simulator, the seed's reach controllers and GPS, the study
toolkit, the annotations, the eye renderer and the command line. They build on the core and I/O.
"""
