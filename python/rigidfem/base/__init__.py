"""What every layer uses: the argument converter (``_checks``, on the bindings' one rule), Ctrl-C in long Python
computations (``_interrupt``), progress bars, pickling as a recipe (``persistence``), notebook displays
(``display``) and the exports to tables, CSV and NumPy archives (``export``). Imports nothing of the package but
the compiled core."""
