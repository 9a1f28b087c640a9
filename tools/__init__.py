"""Developer tools: the OSRM router for tests, benchmarks and one's own region."""
