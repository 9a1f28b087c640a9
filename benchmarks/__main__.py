"""Run every benchmark: ``python -m benchmarks`` (``make bench``)."""

from benchmarks import bench_energy, bench_planner

for module in (bench_energy, bench_planner):
    module.main()
