"""Files: the HDF5 datasets of simulated runs (``dataset``), a measured log written (``logfiles``; read by :mod:`faultgen.logs`)
and atomic writes (``atomic``). Above ``simulation``."""
