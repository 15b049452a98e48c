"""Maintainers' benchmarks of rigidfem, kept out of the installed package.

Run from the root of a checkout (the package installed)::

    python -m benchmarks scaling [--quick] [--output DIR]
    python -m benchmarks peers [--quick] [--output DIR]

``scaling`` (``benchmarks.scaling``): cost of forward dynamics and of the O(n) implicit
step against the number of coordinates. ``peers`` (``benchmarks.peers``): rigidfem
against Pinocchio and MuJoCo (``pip install pin mujoco``). Each writes its tables as CSV
into the output folder (default ``bench/``) and prints them as markdown. The benchmarks
import ``rigidfem``; the package never imports them.
"""
