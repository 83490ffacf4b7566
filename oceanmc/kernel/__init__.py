"""The compiled world: Numba functions over component records, flat pools, integer model ids and
floats only (records.py describes the layout; compile.py how it is compiled and cached).

Nothing here imports the Python side (config, scene packers, run); oceanmc/scene/ packs the
records for it. Importing this package, or models.py and records.py alone, costs nothing: numba
is imported by the modules that hold compiled functions. Everything is importable and testable
with NUMBA_DISABLE_JIT=1.
"""
