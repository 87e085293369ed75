"""Files: the HDF5 datasets of simulated runs (``dataset``), measured robot logs (``measured``)
and atomic writes (``atomic``). Above ``simulation``."""
