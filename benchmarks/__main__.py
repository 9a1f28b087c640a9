"""Run every benchmark: ``python -m benchmarks`` (``make bench``)."""

from benchmarks import bench_energy, bench_http, bench_planner, bench_studies

for module in (bench_energy, bench_planner, bench_studies, bench_http):
    module.main()
