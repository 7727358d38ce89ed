"""``shipblock bench``: the benchmarks (:mod:`shipblock.bench`)."""

from __future__ import annotations

import sys
from pathlib import Path

from shipblock.cli._common import UserError


def cmd_bench(args):
    if args.read:
        import json

        from shipblock.bench.readers import reader_throughput, write_reader_throughput

        result = reader_throughput(args.read, min_seconds=0.3 if args.quick else 1.0)
        write_reader_throughput(result, sys.stdout)
        if args.output:
            Path(args.output).write_text(json.dumps(result, indent=2))
        return 0
    from shipblock.bench.run import run_benchmarks

    if args.campaign_runs is not None and args.campaign_runs < 0:
        raise UserError(f"--campaign-runs must be >= 0, got {args.campaign_runs}")
    if args.chunk_size is not None and args.chunk_size < 1:
        raise UserError(f"--chunk-size must be >= 1, got {args.chunk_size}")
    dask_workers = None
    if args.dask:
        try:
            dask_workers = [int(n) for n in args.dask.split(",")]
        except ValueError:
            raise UserError(f"--dask takes numbers of workers like 1,2; got {args.dask!r}") from None
        if min(dask_workers) < 1:
            raise UserError(f"--dask: numbers of workers must be >= 1, got {args.dask!r}")
    return run_benchmarks(quick=args.quick, pyslammer=not args.no_pyslammer, output=args.output,
                          campaign_runs=args.campaign_runs, chunk_size=args.chunk_size,
                          profile=args.profile, cold=not args.no_cold_start,
                          dask_workers=dask_workers)
