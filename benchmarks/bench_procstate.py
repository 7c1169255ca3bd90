"""The pacing's reading of a process (``sim.procstate.read_process_state``): CPU time per
reading of a process of 15 idle threads, as a student's rclpy node has with Fast DDS's.

    python benchmarks/bench_procstate.py [--readings 5000] [--threads 14]
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import time

from sim.procstate import read_process_state

PROGRAM = """\
import sys, threading, time
for _ in range(int(sys.argv[1])):
    threading.Thread(target=time.sleep, args=(600,), daemon=True).start()
print("up", flush=True)
time.sleep(600)
"""


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--readings", type=int, default=5000)
    parser.add_argument("--threads", type=int, default=14, help="besides the main thread")
    args = parser.parse_args()
    process = subprocess.Popen([sys.executable, "-c", PROGRAM, str(args.threads)],
                               stdout=subprocess.PIPE, text=True)
    try:
        assert process.stdout is not None and process.stdout.readline() == "up\n"
        began = time.process_time()
        for _ in range(args.readings):
            read_process_state(process.pid)
        each = (time.process_time() - began) / args.readings
        print(f"{each * 1e6:.0f} us of CPU a reading of a {args.threads + 1}-thread process")
    finally:
        process.kill()
        process.wait()


if __name__ == "__main__":
    main()
