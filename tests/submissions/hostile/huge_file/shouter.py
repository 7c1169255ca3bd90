"""Hostile: writes a huge file into its working directory."""
chunk = b'x' * (1024 * 1024)
with open('huge.bin', 'wb') as fh:
    while True:
        fh.write(chunk)
