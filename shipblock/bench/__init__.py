"""Benchmarks behind ``shipblock bench``: measured, never asserted in unit tests.

The top layer of the package, beside the command line and the plots (docs/architecture.rst);
nothing in the library imports it.

=====================================  =======================================================
:mod:`~shipblock.bench.run`            :func:`~shipblock.bench.run.run_benchmarks`: all of
                                       them, the report and its JSON
:mod:`~shipblock.bench.solver`         samples and runs per second, batch scaling, accuracy,
                                       pySLAMMER
:mod:`~shipblock.bench.campaign`       a generated pipeline in a subprocess: time, memory
:mod:`~shipblock.bench.parallel`       a batch beside a busy core; Dask LocalClusters
:mod:`~shipblock.bench.startup`        the demo command from an empty numba cache
:mod:`~shipblock.bench.readers`        files per second of the record readers
:mod:`~shipblock.bench.timing`         timing on a shared machine; the benchmark systems and
                                       records
:mod:`~shipblock.bench.targets`        the targets and the verdicts on them
=====================================  =======================================================
"""
