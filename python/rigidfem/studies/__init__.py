"""Studies over many runs: speed against error (``study``, ``python -m rigidfem bench``), the resolution a
tolerance needs (``resolve``), parameter sweeps (``sweep``: threads, processes, Dask) and the demo. Imports every
layer below."""
