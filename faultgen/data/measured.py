"""The measured-log reader's old path, named in docs/: moved to :mod:`faultgen.logs.measured` (its writers to :mod:`faultgen.data.logfiles`)."""
from faultgen.logs.measured import MeasuredData, MeasuredDataError, from_arrays, from_columns, read  # noqa: F401,E501
