"""The model every other part shares: exercises, results, content files, errors, settings."""
