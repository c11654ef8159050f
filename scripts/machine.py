"""The machine a measurement ran on, for the first line of the scripts' reports.

The speed figures of issue notes are only comparable on one kind of machine. The same binary
solved the paper's room at 1024² in 0.18 s on one 2-core machine of this workplace and in
0.40 s on another, an AMD EPYC of family 23, model 1 (Zen 1, whose vector units are 128 bits
wide: AVX2's 8-wide loops ran no faster there than SSE's 4-wide ones). pyamg took 4.1 s on
the first and 4.7-4.9 s on the second, so the ratio of the two went from 18.7x to 10.1x. So
every report says where it was measured.

    python3 scripts/machine.py
"""

import os
import platform


def cpu():
    """The processor's model name, with its x86 family and model when Linux tells them."""
    fields = {}
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                key, _, value = line.partition(":")
                key = key.strip()
                if key in ("model name", "cpu family", "model") and key not in fields:
                    fields[key] = value.strip()
                if not line.strip() and fields:
                    break
    except OSError:
        pass
    name = fields.get("model name") or platform.processor() or platform.machine()
    if "cpu family" in fields and "model" in fields:
        name += f" (family {fields['cpu family']}, model {fields['model']})"
    return name


def describe():
    """One line: the processor, the cores this process may use, the system."""
    try:
        cores = len(os.sched_getaffinity(0))
    except AttributeError:
        cores = os.cpu_count()
    return f"machine: {cpu()}, {cores} cores, {platform.system()} {platform.release()}"


if __name__ == "__main__":
    print(describe())
