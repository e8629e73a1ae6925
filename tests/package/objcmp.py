"""objcmp.py [--tol T] [--tol-KEY T] A B: compares two OBJ-like text files number by number.

Same lines, same words; a word that is a number in both may differ by at most
T * max(1, |a|) (default T = 1e-12); --tol-vn 1e-8 sets the tolerance of the lines starting
with `vn` (any first word). Prints "same (max diff D)" (per first word when tolerances differ)
or the first difference; exit 0 when the files agree. Used by tests/package/run_wine.sh."""
import sys


def number(word):
    try:
        return float(word)
    except ValueError:
        return None


def compare(a_path, b_path, tol, key_tol):
    with open(a_path) as fa, open(b_path) as fb:
        a_lines, b_lines = fa.read().splitlines(), fb.read().splitlines()
    if len(a_lines) != len(b_lines):
        return "%d lines vs %d" % (len(a_lines), len(b_lines)), None
    worst = {}
    for i, (la, lb) in enumerate(zip(a_lines, b_lines), 1):
        wa, wb = la.split(), lb.split()
        if len(wa) != len(wb):
            return "line %d: %r vs %r" % (i, la, lb), None
        key = wa[0] if wa and wa[0] in key_tol else ""
        t = key_tol.get(key, tol)
        for x, y in zip(wa, wb):
            if x == y:
                continue
            fx, fy = number(x), number(y)
            if fx is None or fy is None:
                return "line %d: %r vs %r" % (i, la, lb), None
            d = abs(fx - fy) / max(1.0, abs(fx))
            worst[key] = max(worst.get(key, 0.0), d)
            if not d <= t:
                return "line %d: %r vs %r (diff %.3g)" % (i, la, lb, d), None
    return None, worst


def main(argv):
    tol, key_tol = 1e-12, {}
    while len(argv) > 2 and argv[0].startswith("--tol"):
        if argv[0] == "--tol":
            tol = float(argv[1])
        else:
            key_tol[argv[0][len("--tol-"):]] = float(argv[1])
        argv = argv[2:]
    if len(argv) != 2:
        print(__doc__)
        return 2
    problem, worst = compare(argv[0], argv[1], tol, key_tol)
    if problem:
        print("DIFFERENT: " + problem)
        return 1
    if not key_tol:
        print("same (max diff %.3g)" % worst.get("", 0.0))
    else:
        print("same (max diff %s)" % ", ".join(
            "%s %.3g" % (k or "other", worst.get(k, 0.0)) for k in [""] + sorted(key_tol)))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
