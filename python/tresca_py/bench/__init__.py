"""Benchmark helpers (make bench): the factorisation peers of verification/bench/factorisation.py."""
