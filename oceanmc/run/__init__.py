"""The run, following the data: simulation.py packs a scene (prepare) and traces its batches on
the compiled kernel (compiling.py compiles or loads it); derivation.py turns the batch tallies
into a Result (result.py: the model), derived.py the apparent optical properties of one;
merge.py combines runs, resume.py continues a partial one (`oceanmc run --resume`);
format.py writes a Result into its HDF5 file, placed atomically (placement.py), hdf5.py reads it
back; summary.py prints it. results.py gathers the names users import."""
