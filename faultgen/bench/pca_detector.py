"""The ``pca`` baseline's class, :class:`analysis.pca_detector.PCADetector`, under its earlier name
(``faultgen.bench.pca_detector:PCADetector`` and ``faultgen.bench.baselines:PCADetector`` still name
it as a plug-in)."""

from analysis.pca_detector import PCADetector

__all__ = ["PCADetector"]
