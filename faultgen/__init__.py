"""faultgen: labelled wear-fault data for industrial robots, simulated in MuJoCo.

Data flows one way: ``robots`` (models) -> simulation -> dataset -> ``analysis``.
"""

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("faultgen")
except PackageNotFoundError:  # running from a source tree that was not installed
    __version__ = "0.0.0+unknown"
