"""The robot models: MJCF loading, nominal parameters, the effects a robot carries and its inverse
dynamics (``robots``); the drivetrain as data (``drivetrain``), the one builder that adds it to an
arm (``builder``), the arm readers for URDF, xacro, MJCF and DH tables (``importers``), the
drivetrain sizing rules (``sizing``) and the writer of a robot folder (``folder``, below
``faultgen robots add``). Imports only :mod:`faultgen.effects`, the layer below."""
