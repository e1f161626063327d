"""Timing peers for the page's benchmarks (npm run bench -- peers)."""
