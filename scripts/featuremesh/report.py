"""The benchmarks' output: one table as OUT.csv and as OUT.md under a title line, printed too."""
import csv
import os


def write_table(out, rows, keys, title):
    os.makedirs(os.path.dirname(os.path.abspath(out)), exist_ok=True)
    with open(out + ".csv", "w", newline="") as f:
        w = csv.DictWriter(f, keys)
        w.writeheader()
        w.writerows(rows)
    lines = [title, "", "| " + " | ".join(keys) + " |", "|" + "---|" * len(keys)]
    for r in rows:
        lines.append("| " + " | ".join(("%.3f" % r[k]) if isinstance(r[k], float) else str(r[k]) for k in keys) + " |")
    with open(out + ".md", "w") as f:
        f.write("\n".join(lines) + "\n")
    print("\n".join(lines))


HUGE_PAGES = "glibc.malloc.hugetlb=1"


def use_huge_pages(argv):
    """Re-runs this script (argv: sys.argv) under pvpython with glibc's malloc asking for transparent huge pages (THP 'madvise'
    mode), so every buffer, the voxel cut's and TetGen's included, faults 2 MB at a time."""
    if HUGE_PAGES not in os.environ.get("GLIBC_TUNABLES", ""):
        env = dict(os.environ, GLIBC_TUNABLES=":".join(filter(None, (os.environ.get("GLIBC_TUNABLES"), HUGE_PAGES))))
        import shutil
        import sys
        pvpython = shutil.which("pvpython") or sys.executable
        os.execve(pvpython, [pvpython] + list(argv), env)


def fresh_page_ms(megabytes=128, runs=3):
    """Milliseconds to fault in 100 MB of fresh memory through malloc (numpy's own allocator asks
    for huge pages, so it would not show what C++ buffers cost), the median of a few tries."""
    import ctypes
    import time
    libc = ctypes.CDLL(None)
    libc.malloc.restype = ctypes.c_void_p
    libc.malloc.argtypes = [ctypes.c_size_t]
    libc.free.argtypes = [ctypes.c_void_p]
    libc.memset.argtypes = [ctypes.c_void_p, ctypes.c_int, ctypes.c_size_t]
    times = []
    for _ in range(runs):
        size = megabytes << 20
        t = time.perf_counter()
        block = libc.malloc(size)
        libc.memset(block, 1, size)
        times.append(time.perf_counter() - t)
        libc.free(block)
    return sorted(times)[len(times) // 2] * 1e3 * 100.0 / megabytes


def machine():
    """The machine line of every benchmark: cores, system, and the cost of fresh memory, which
    decides much of a large buffer's first pass (a VM's page faults cost 10x a workstation's)."""
    import platform
    huge = HUGE_PAGES in os.environ.get("GLIBC_TUNABLES", "")
    return "%s, %d cores, %s; fresh memory %.0f ms per 100 MB (%s)" % (
        platform.machine(), os.cpu_count(), platform.platform(), fresh_page_ms(),
        "malloc with transparent huge pages" if huge else "default malloc")
