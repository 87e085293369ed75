"""Simulating a run: the servo drives (``control``), sampling, noise and monitoring aggregates
(``sensors``) and the stepping of recorded cycles in MuJoCo (``stepping``). Above ``operation``."""
