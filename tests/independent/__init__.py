"""Independent truth generators: physics written apart from the package, to check it."""
