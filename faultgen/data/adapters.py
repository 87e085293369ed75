"""The log formats' old path, named in docs/ as the place to register a format: moved to :mod:`faultgen.logs.formats` (``Adapter`` is ``LogFormat``, ``ADAPTERS`` is ``FORMATS``)."""
from faultgen.logs.formats import FORMATS as ADAPTERS, MEASURED, LogFormat as Adapter, make, register, torque_source  # noqa: F401,E501
