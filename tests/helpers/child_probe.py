"""A tiny `python -m` module for process-start tests: reports how it was started, then ends.

`python -m tests.helpers.child_probe report CODE`: prints its argument vector, the environment
variable PROBE_VALUE, its process group and name, then exits with CODE.
`python -m tests.helpers.child_probe sleep`: prints SLEEPING and sleeps until it is stopped; SIGUSR1
writes its stacks to its output, as the robot side's processes do (tiago_sim.node_main).
"""

from __future__ import annotations

import json
import os
import sys
import time

from tiago_sim.node_main import stacks_on_sigusr1


def main() -> int:
    mode = sys.argv[1]
    if mode == "sleep":
        stacks_on_sigusr1()
        print("SLEEPING", flush=True)
        while True:
            time.sleep(1.0)
    report = {
        "argv": sys.argv[1:],
        "probe_value": os.environ.get("PROBE_VALUE"),
        "pid": os.getpid(),
        "pgid": os.getpgid(0),
        "parent": os.getppid(),
        "name": open("/proc/self/comm").read().strip(),
    }
    print(json.dumps(report), flush=True)
    return int(sys.argv[2])


if __name__ == "__main__":
    sys.exit(main())
