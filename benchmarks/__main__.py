"""Run every benchmark: ``python -m benchmarks`` (``make bench``)."""

from benchmarks import bench_energy

for module in (bench_energy,):
    module.main()
