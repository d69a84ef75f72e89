#!/usr/bin/env python3
"""Replays error-budget searches on measured curves, to choose a codec's prior slope and bend.

The curves are `scripts/budget_curves.sh` CSVs (name,bit depth,quality,vertex RMSE,bytes); a clip's
error at a quality is interpolated log-linearly between its points in the log of the IJG scale.
`--switch NAME=Q` says from which quality 10-bit pictures widen on that clip (90 without one); the
search codes 12-bit ones from there, but never at or below its first encode's quality 50, which is
coded at 10 bits (`deeper_from`): points at the other depth are left out. `--from-second` follows
the bend from the second encode only (as JPEG's). The search is `src/encoder/budget.rs` and `budget_line.rs` for an error budget, rewritten
here to replay it (first encode at quality 50, aim 1.5 % under the bound, the prior slope and bend
after one encode, the secant and bend after two, inside a bracket the bent root, the nearest
secant or regula falsi; the jump stop; qualities in hundredths): keep the two in step.

    scripts/budget_sim.py curves.csv --switch pcow=72.75 --try 1.0,0 1.0,-1.0 0.9,-1.0
"""
import argparse
import collections
import math


def ijg(q):
    q = max(1, min(100, q))
    return max(1, 5000 // q if q < 50 else 200 - 2 * q)


def log_scale(q):
    lo = math.floor(q)
    if lo >= 100:
        return 0.0
    a, b = math.log(ijg(lo)), math.log(ijg(lo + 1))
    return a + (q - lo) * (b - a)


def quality_of(u):
    scale = lambda q: math.log(ijg(q))
    q = next((q for q in range(1, 100) if scale(q + 1) <= u), 99)
    a, b = scale(q), scale(q + 1)
    t = (a - u) / (a - b) if a > b else 0.0
    return min(100.0, max(1.0, round((q + min(1.0, max(0.0, t))) * 100) / 100))


def bracket(points, aim):
    best = None
    ordered = sorted(points)
    for p, q in zip(ordered, ordered[1:]):
        if (p[1] > aim) != (q[1] > aim):
            below, above = (q, p) if p[1] > aim else (p, q)
            near = min(abs(below[1] - aim), abs(above[1] - aim))
            if best is None or near < best[0]:
                best = (near, below, above)
    return best and best[1:]


def next_log_scale(points, aim, prior, bend, top, from_first=True):
    """Where the search's model puts the aim; `bend` holds at log scales up to `top`."""
    curvature = lambda a, b: bend if max(a, b) <= top + 1e-12 else 0.0
    found = bracket(points, aim)
    if found:
        below, above = found
        lo, hi = sorted((below[0], above[0]))
        inside = lambda u: lo + 0.02 * (hi - lo) < u < hi - 0.02 * (hi - lo)
        c = curvature(lo, hi)
        if len(points) == 2 and c:
            slope = (above[1] - below[1]) / (above[0] - below[0])
            f = lambda u: below[1] + slope * (u - below[0]) + 0.5 * c * (u - below[0]) * (u - above[0]) - aim
            a, b = lo, hi
            if f(a) * f(b) < 0:
                for _ in range(100):
                    m = (a + b) / 2
                    a, b = (m, b) if (f(m) < 0) == (f(a) < 0) else (a, m)
                if inside((a + b) / 2):
                    return (a + b) / 2
        p, q = sorted(points, key=lambda p: abs(p[1] - aim))[:2]
        slope = (q[1] - p[1]) / (q[0] - p[0])
        u = p[0] + (aim - p[1]) / slope
        if slope * prior > 0 and math.isfinite(u) and inside(u):
            return u
        t = min(0.9, max(0.1, (aim - below[1]) / (above[1] - below[1])))
        return below[0] + t * (above[0] - below[0])
    last = points[-1]
    if len(points) >= 2:
        before = points[-2]
        s = (last[1] - before[1]) / (last[0] - before[0]) + 0.5 * curvature(last[0], before[0]) * (last[0] - before[0])
        slope = math.copysign(min(abs(prior) * 4, max(abs(prior) / 4, abs(s))), prior) if s * prior > 0 else prior
        return last[0] + (aim - last[1]) / slope
    straight = (aim - last[1]) / prior
    if bend and from_first:
        a, b, c = 0.5 * bend, prior, last[1] - aim
        disc = b * b - 4 * a * c
        if disc >= 0:
            roots = [d for d in ((-b + math.sqrt(disc)) / (2 * a), (-b - math.sqrt(disc)) / (2 * a)) if d * straight > 0]
            if roots:
                d = min(roots, key=abs)
                if curvature(last[0], last[0] + d):
                    return last[0] + d
    return last[0] + straight


def jumps(points, aim, prior):
    found = bracket(points, aim)
    if not found:
        return False
    below, above = found
    width = abs(above[0] - below[0])
    return 0 < width < 0.04 and abs(above[1] - below[1]) > 3 * abs(prior) * width


def search(error, limit, prior, bend, from_first=True):
    """Encodes made, the error kept, whether it landed within 3 %."""
    aim, top = math.log(limit * 0.985), log_scale(50)
    points, qualities, best, q = [], [], None, 50.0
    while True:
        e = error(q)
        points.append((log_scale(q), math.log(e)))
        qualities.append(q)
        if e <= limit and (best is None or e > best):
            best = e
        if best and limit * 0.97 <= best <= limit:
            return len(qualities), best, True
        if len(qualities) >= 10 or (best and jumps(points, aim, prior)):
            return len(qualities), best, False
        u = next_log_scale(points, aim, prior, bend, top, from_first)
        q = quality_of(min(log_scale(1), max(log_scale(100), u)))
        while q in qualities:
            q = round((q + 0.01) * 100) / 100
            if q > 100 or best:
                return len(qualities), best, False


def curves(paths, switch):
    points = collections.defaultdict(list)
    for path in paths:
        for line in open(path):
            name, depth, q, e, _ = line.strip().split(",")
            q = float(q)
            wanted = 12 if q >= max(switch.get(name, 90.0), 50.01) else 10
            if depth == "auto" or int(depth) == wanted:
                points[name].append((log_scale(q), math.log(float(e))))

    def error_of(name):
        pts = sorted(points[name])

        def error(q):
            u = log_scale(q)
            pairs = list(zip(pts, pts[1:]))
            (u0, e0), (u1, e1) = next(((a, b) for a, b in pairs if a[0] <= u <= b[0]),
                                      pairs[0] if u < pts[0][0] else pairs[-1])
            return math.exp(e0 + (u - u0) / (u1 - u0) * (e1 - e0))
        return error
    return {name: error_of(name) for name in points}


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("curves", nargs="+")
    parser.add_argument("--switch", nargs="*", default=[], metavar="NAME=Q")
    parser.add_argument("--limits", default="3e-4,2e-4,1.5e-4,1e-4,7e-5")
    parser.add_argument("--try", dest="tries", nargs="+", default=["1.0,0"], metavar="PRIOR,BEND")
    parser.add_argument("--from-second", action="store_true")
    args = parser.parse_args()
    switch = {k: float(v) for k, v in (s.split("=") for s in args.switch)}
    errors = curves(args.curves, switch)
    limits = [float(x) for x in args.limits.split(",")]
    for attempt in args.tries:
        prior, bend = map(float, attempt.split(","))
        total, missed, over = 0, 0, []
        for name, error in errors.items():
            for limit in limits:
                encodes, _, landed = search(error, limit, prior, bend, not args.from_second)
                total += encodes
                missed += not landed
                if encodes > 3 or not landed:
                    over.append("%s %g: %d%s" % (name, limit, encodes, "" if landed else " (not within)"))
        print("prior %.2f bend %.2f: %d encodes, %d not within; over 3: %s" % (prior, bend, total, missed, ", ".join(over)))


if __name__ == "__main__":
    main()
