"""The run: simulation.py traces a packed scene on the compiled kernel (compiling.py compiles
or loads it), results.py turns the batch tallies into a Result, hdf5.py writes and reads it."""
