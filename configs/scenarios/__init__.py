"""Simulator scenarios, one YAML file each."""
