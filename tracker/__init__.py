"""People tracking on top of the moving-object detector: pairing, tracks, and the
application shell around them (readers, writers, CLI, evaluation, visualisation)."""
