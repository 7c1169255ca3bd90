"""Hostile: floods stdout and stderr."""
import sys

line = 'spam ' * 200 + '\n'
while True:
    sys.stdout.write(line)
    sys.stderr.write(line)
