"""How a robot is operated: its tasks as time-parameterised joint paths (``tasks``, with the
inverse kinematics of ``ik``) and the wear schedules over cycles (``wear``). Above ``model``."""
