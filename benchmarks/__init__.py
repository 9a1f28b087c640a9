"""Speed and quality benchmarks: ``make bench`` runs them all and prints tables."""
