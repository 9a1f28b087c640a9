"""What the tests and the benchmarks share — the reference instances read into problems, days
that look real, the service and outside services as processes — so that neither imports the
other."""
