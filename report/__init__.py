"""Documentation generators: `make report` writes docs/paper-reproduction.md."""
