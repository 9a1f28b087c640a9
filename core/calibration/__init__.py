"""Fitting the model's parameters to a van's measured trips (:mod:`core.calibration.fit`)."""
