"""Fault detection and isolation modules for faultgen datasets, in scikit-learn style.

Planned layout (see docs/architecture.md): features, monitoring (PCA T2 / Q), classify,
isolation (transfer entropy, cross-correlation) and benchmark. Nothing is implemented yet.
"""
