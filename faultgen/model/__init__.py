"""The robot models: MJCF loading, nominal parameters, inverse dynamics (``robots``) and the
motor-side friction models (``friction``). The lowest layer: imports nothing else of faultgen."""
