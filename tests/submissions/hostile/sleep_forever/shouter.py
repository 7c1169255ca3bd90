"""Hostile: sleeps forever at import; no node is ever created."""
import time

time.sleep(10**9)
