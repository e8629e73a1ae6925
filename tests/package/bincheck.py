"""bincheck.py KIND DIR [TBD]: checks the native files of one platform's package payload without
running them (tests/package/run_package.sh). DIR is $(B)/<platform>/ (library, CLI, OpenBLAS) or
a staged package folder; each file named below that exists in DIR is checked, one line each.

  elf DIR        linux-x64: every ELF's symbol versions GLIBC_x <= 2.28 (Blender's Linux floor),
                 its NEEDED libraries glibc's or bundled in DIR (nothing from Debian: no
                 lapack/blas/gfortran), RPATH/RUNPATH $ORIGIN when it needs a bundled library,
                 and `ldd -r` finds every library and symbol (this machine's newer glibc).
  pe DIR         windows-x64: every PE imports only Windows' own DLLs (KERNEL32, the UCRT's
                 api-ms-win-crt-*) or DLLs bundled in DIR (no libwinpthread/libgcc/MSVC runtime).
  macho DIR TBD  macos-*: the Mach-O link check: right CPU, minos <= 11.0, a code signature on
                 arm64 (which refuses unsigned code), every LC_LOAD_DYLIB /usr/lib/libSystem.B.dylib or
                 @rpath/<a library bundled in DIR> with LC_RPATH @loader_path, and every undefined
                 symbol bound (two-level namespace) to libSystem and exported by it (TBD: the
                 SDK's libSystem.tbd, from Zig) or to a bundled library that defines it.
Prints one line per file and "N passed, N failed"; exit 1 if any check fails."""
import os
import re
import shutil
import subprocess
import sys

MAX_GLIBC = (2, 28)
GLIBC_LIBS = {"libc.so.6", "libm.so.6", "libpthread.so.0", "libdl.so.2", "librt.so.1",
              "ld-linux-x86-64.so.2"}
NATIVE = ("libccnurbs.so", "ccnurbs", "libscipy_openblas.so", "loadcheck/loadcheck",
          "ccnurbs.dll", "ccnurbs.exe", "libscipy_openblas.dll", "loadcheck/loadcheck.exe",
          "libccnurbs.dylib", "libscipy_openblas.dylib")
MACHO_CPU = {"macos-arm64": "ARM64", "macos-x64": "X86_64"}


def tool(name):
    for n in (name, name + "-14", name + "-15", name + "-16"):
        if shutil.which(n):
            return n
    raise SystemExit("bincheck: %s not found (make deps installs llvm/binutils)" % name)


def run(*cmd):
    r = subprocess.run(cmd, capture_output=True, text=True)
    return r.stdout + r.stderr


def files(d):
    return [os.path.join(d, f) for f in NATIVE if os.path.isfile(os.path.join(d, f))]


def check_elf(path, bundled):
    problems = []
    versions = set(re.findall(r"GLIBC_(\d+)\.(\d+)", run("objdump", "-T", path)))
    newest = max(((int(a), int(b)) for a, b in versions), default=(0, 0))
    if newest > MAX_GLIBC:
        problems.append("needs GLIBC_%d.%d" % newest)
    dyn = run("readelf", "-d", path)
    needed = re.findall(r"\(NEEDED\)\s+Shared library: \[([^\]]+)\]", dyn)
    paths = re.findall(r"\((?:RPATH|RUNPATH)\)\s+Library r(?:un)?path: \[([^\]]+)\]", dyn)
    for lib in needed:
        if lib not in GLIBC_LIBS and lib not in bundled:
            problems.append("needs %s (neither glibc nor bundled)" % lib)
    if any(lib in bundled for lib in needed) and not any("$ORIGIN" in p for p in paths):
        problems.append("no $ORIGIN rpath for its bundled libraries")
    ldd = run("ldd", "-r", path)
    for line in ldd.splitlines():
        if "not found" in line or "undefined symbol" in line:
            problems.append(line.strip())
    return problems, "GLIBC_%d.%d, needs %s" % (newest + (" ".join(needed),))


def check_pe(path, bundled):
    out = run(tool("llvm-objdump"), "-p", path)
    imports = sorted(set(re.findall(r"DLL Name: (\S+)", out)))
    problems = []
    if "file format coff-x86-64" not in out and "pe-x86-64" not in out:
        problems.append("not an x86-64 PE file")
    for dll in imports:
        low = dll.lower()
        if not (low == "kernel32.dll" or low.startswith("api-ms-win-crt-") or dll in bundled):
            problems.append("imports %s (neither Windows' nor bundled)" % dll)
    return problems, "imports %s" % " ".join(i for i in imports
                                              if not i.startswith("api-ms-win-crt-")) + \
        " + UCRT"


def tbd_exports(tbd):
    """Symbols exported by the libraries of an SDK .tbd (YAML, tbd v4), per architecture."""
    text = open(tbd).read()
    out = {}
    targets = []
    for m in re.finditer(r"(targets|symbols|weak-symbols|thread-local-symbols):\s*\[([^\]]*)\]",
                         text):
        key, items = m.group(1), [w.strip(" '\"\n") for w in m.group(2).split(",")]
        if key == "targets":
            targets = [t.split("-")[0] for t in items if t]
        else:
            for t in targets:
                out.setdefault(t, set()).update(i for i in items if i)
    return out


def check_macho(path, platform, bundled, exports):
    nm, objdump = tool("llvm-nm"), tool("llvm-objdump")
    problems = []
    hdr = run(objdump, "--macho", "--private-header", path)
    if MACHO_CPU[platform] not in hdr.split():
        problems.append("not %s" % MACHO_CPU[platform])
    lc = run(objdump, "--macho", "--private-headers", path)
    minos = re.findall(r"minos (\d+)\.(\d+)", lc) + re.findall(
        r"LC_VERSION_MIN_MACOSX\s+cmdsize \d+\s+version (\d+)\.(\d+)", lc)
    if not minos or max((int(a), int(b)) for a, b in minos) > (11, 0):
        problems.append("minimum macOS %s (want <= 11.0)" % (minos,))
    if platform == "macos-arm64" and "LC_CODE_SIGNATURE" not in lc:
        problems.append("not signed (arm64 macOS refuses unsigned code)")
    own_id = re.findall(r"cmd LC_ID_DYLIB\s+cmdsize \d+\s+name (\S+)", lc)
    dylibs = re.findall(r"cmd LC_(?:LOAD|LOAD_WEAK|REEXPORT)_DYLIB\s+cmdsize \d+\s+name (\S+)", lc)
    rpaths = re.findall(r"cmd LC_RPATH\s+cmdsize \d+\s+path (\S+)", lc)
    for d in dylibs:
        if d == "/usr/lib/libSystem.B.dylib":
            continue
        if d.startswith("@rpath/") and d[7:] in bundled and "@loader_path" in rpaths:
            continue
        if d.startswith("@loader_path/") and d[13:] in bundled:
            continue
        problems.append("loads %s (neither libSystem nor bundled via @loader_path)" % d)
    arch = "arm64" if platform == "macos-arm64" else "x86_64"
    sys_syms = exports.get(arch, set())
    bundled_syms = {}
    unresolved = []
    n_undef = 0
    for line in run(nm, "-m", path).splitlines():
        if "(undefined)" not in line:
            continue
        n_undef += 1
        m = re.search(r"external (\S+) \(from ([^)]+)\)", line)
        if not m:
            unresolved.append(line.strip())
            continue
        sym, lib = m.groups()
        if lib == "libSystem":
            ok = sym in sys_syms
        else:
            name = lib + ".dylib"
            if name not in bundled:
                unresolved.append("%s from %s (not bundled)" % (sym, lib))
                continue
            if name not in bundled_syms:
                bundled_syms[name] = set(run(nm, "-gU", "-j", os.path.join(os.path.dirname(path),
                                                                             name)).split())
            ok = sym in bundled_syms[name]
        if not ok:
            unresolved.append("%s (from %s)" % (sym, lib))
    if unresolved:
        problems.append("%d unresolved: %s" % (len(unresolved), ", ".join(unresolved[:8])))
    return problems, "%s, %d undefined symbols all resolved, loads %s%s" % (
        MACHO_CPU[platform], n_undef, " ".join(os.path.basename(d) for d in dylibs),
        (", id " + own_id[0]) if own_id else "")


def main(argv):
    if len(argv) < 2 or argv[0] not in ("elf", "pe", "macho"):
        print(__doc__)
        return 2
    kind, d = argv[0], argv[1]
    platform = os.path.basename(os.path.normpath(d))
    todo = files(d)
    bundled = {os.path.basename(f) for f in todo}
    exports = tbd_exports(argv[2]) if kind == "macho" else None
    passed = failed = 0
    if not todo:
        print("FAIL  %s: no native files" % d)
        failed += 1
    for f in todo:
        if kind == "elf":
            problems, info = check_elf(f, bundled)
        elif kind == "pe":
            problems, info = check_pe(f, bundled)
        else:
            problems, info = check_macho(f, platform, bundled, exports)
        rel = os.path.relpath(f, d)
        if problems:
            failed += 1
            print("FAIL  %s/%s: %s" % (platform, rel, "; ".join(problems)))
        else:
            passed += 1
            print("ok    %s/%s: %s" % (platform, rel, info))
    print("%d passed, %d failed" % (passed, failed))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
