"""The robot models: one constant model of a robot, its nominal parameters, the effects it carries
and its inverse dynamics (``robot``: :class:`~faultgen.model.robot.Robot`), resolved once from a
name, folder or MJCF file (``robots``); the drivetrain as data (``drivetrain``), the one builder that
adds it to an arm (``builder``), the arm importers for URDF and xacro (``import_urdf``), MJCF
(``import_mjcf``) and DH tables (``import_dh``) behind one registry (``importers``; what they return:
``arm``), the drivetrain sizing rules (``sizing``) and the writer of a robot folder (``folder``,
below ``faultgen robots add``). Imports only :mod:`faultgen.effects`, the layer below."""
