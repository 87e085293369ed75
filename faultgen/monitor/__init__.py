"""Monitor a fleet's own robots: measured logs in, a PCA monitor learned on each unit's first logs
against its twin, alarms and the worn axis out (:func:`faultgen.monitor.loop.monitor`)."""
