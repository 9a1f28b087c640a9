"""Run every benchmark: ``python -m benchmarks`` (``make bench``)."""

from benchmarks import (
    bench_calibration,
    bench_cold_chain,
    bench_cold_chain_robust,
    bench_electrification,
    bench_energy,
    bench_evrptw,
    bench_fleet,
    bench_homberger,
    bench_limits,
    bench_planner,
    bench_roads,
    bench_serving,
    bench_soak,
    bench_studies,
    evrptw,
)

# the replays' worker processes import this module again: only the parent runs the benchmarks
if __name__ == "__main__":
    for module in (
        bench_energy,
        bench_planner,
        bench_roads,
        bench_studies,
        bench_electrification,
        bench_cold_chain,
        bench_cold_chain_robust,
        bench_calibration,
        bench_limits,
        bench_fleet,
        bench_homberger,
        evrptw,
        bench_evrptw,
        bench_serving,
        bench_soak,
    ):
        module.main()
