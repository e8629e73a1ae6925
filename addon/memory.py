"""Levels that fit: a limit mesh's memory, estimated before its plan is built, against the memory
the machine has free.

Each level multiplies the faces by four, so one keystroke in a Levels field can ask for more
memory than the machine has. Where the system over-commits memory (Linux) the process is then
killed, Blender with it and the unsaved work; elsewhere it swaps for minutes. So a plan whose
estimate exceeds 80 % of the free memory is refused with a message (the panel shows it and the
last valid limit stays), before anything is allocated.

The estimate is per face of the limit mesh: the plan, the evaluation's arrays and Blender's mesh
together peak at 1.0-1.4 kB per face (Suzanne at levels 4-5 on Blender 3.4 and 4.5, with and
without its UV map); BYTES_PER_FACE takes the top of that range with a margin.
"""
import ctypes
import os
import sys

BYTES_PER_FACE = 1600
FRACTION = 0.8


def limit_faces(face_sizes, levels):
    """Faces of the limit mesh: 4^L per quad, n 4^(L-1) per n-gon (split once first)."""
    quads = int((face_sizes == 4).sum())
    others = int(face_sizes[face_sizes != 4].sum())
    return quads * 4 ** levels + others * 4 ** max(levels - 1, 0)


def _windows_free():
    class Status(ctypes.Structure):
        _fields_ = [("length", ctypes.c_ulong), ("load", ctypes.c_ulong),
                    ("total", ctypes.c_ulonglong), ("free", ctypes.c_ulonglong),
                    ("page_total", ctypes.c_ulonglong), ("page_free", ctypes.c_ulonglong),
                    ("virtual_total", ctypes.c_ulonglong), ("virtual_free", ctypes.c_ulonglong),
                    ("extended", ctypes.c_ulonglong)]
    s = Status()
    s.length = ctypes.sizeof(Status)
    return s.free if ctypes.windll.kernel32.GlobalMemoryStatusEx(ctypes.byref(s)) else None


def free_bytes():
    """Memory free for a new plan: Linux's MemAvailable, Windows' available physical memory,
    elsewhere (macOS) the physical memory; None if unknown (then nothing is refused)."""
    try:
        if sys.platform.startswith("linux"):
            with open("/proc/meminfo") as f:
                for line in f:
                    if line.startswith("MemAvailable:"):
                        return int(line.split()[1]) * 1024
        if sys.platform == "win32":
            return _windows_free()
        return os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (OSError, ValueError, AttributeError):
        return None


def refusal(face_sizes, levels, what="Levels Viewport"):
    """A message saying why `levels` cannot be built here, or None if it fits."""
    faces = limit_faces(face_sizes, levels)
    need = faces * BYTES_PER_FACE
    free = free_bytes()
    if free is None or need <= FRACTION * free:
        return None
    return ("levels %d would make %s faces, about %s, but %s of memory is free: lower %s"
            % (levels, _count(faces), _size(need), _size(free), what))


def _count(n):
    return "%.1f million" % (n / 1e6) if n >= 1e6 else "{:,}".format(n)


def _size(b):
    return "%.1f GB" % (b / 2 ** 30) if b >= 2 ** 30 else "%.0f MB" % (b / 2 ** 20)
