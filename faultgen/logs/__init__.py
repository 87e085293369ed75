"""A robot's logs read: the measured format's columns and bounds (``columns``), its whole reader
and checks (``jointlog``, ``measured``), its block reader (``blocks``, ``longlog``: a log too long
to read whole) and the registry of log formats (``formats``: ``measured``, the default, then
``ur-rtde``, ``voraus`` and a user's), each read whole or in blocks with the same checks. Below
``operation`` (the replay reads a log through it), above ``model``."""
