"""mjeap's benchmarks, one module each (``run(args) -> dict``, its section of the JSON),
run side by side by ``python scripts/bench.py`` (``--only NAME``)."""
