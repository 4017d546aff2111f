"""Readers and writers at the edge of the application: recordings, ground truth, CSV files."""
