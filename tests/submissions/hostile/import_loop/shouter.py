"""Hostile: an infinite loop at import; no node is ever created."""
while True:
    pass
