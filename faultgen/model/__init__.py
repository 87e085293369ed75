"""The robot models: MJCF loading, nominal parameters, the effects a robot carries and its inverse
dynamics (``robots``). Imports only :mod:`faultgen.effects`, the layer below."""
