"""Figures of The Algorithmic Beauty of Plants (Prusinkiewicz and Lindenmayer
1990) reproduced exactly.

Expected string lengths and counts of F come from Parikh vectors (the
growth matrix of a DOL system applied n times to the axiom's symbol counts,
computed here with integer numpy), or from a tiny independent reference
implementation for the context-sensitive case, never from the code under
test.
"""

from collections import Counter

import numpy as np
import pytest

from fractalgeo_rs.lsystem import LSystem, turtle_2d, turtle_3d


def parikh(axiom, rules, n):
    """Symbol counts after n parallel steps of a DOL system (exact ints)."""
    symbols = sorted(set(axiom) | set(rules) | {c for v in rules.values() for c in v})
    idx = {c: i for i, c in enumerate(symbols)}
    m = np.zeros((len(symbols), len(symbols)), dtype=object)
    for c in symbols:
        succ = rules.get(c, c)
        for d, k in Counter(succ).items():
            m[idx[d], idx[c]] += k
    v = np.array([Counter(axiom)[c] for c in symbols], dtype=object)
    for _ in range(n):
        v = m.dot(v)
    return {c: int(v[idx[c]]) for c in symbols}


# (figure, axiom, rules, n, symbols drawn as F)
FIGURES = [
    ("1.6 quadratic Koch island", "F-F-F-F", {"F": "F-F+F+FF-F-F+F"}, 3, "F"),
    ("1.7a quadratic Koch island", "F-F-F-F", {"F": "F+FF-FF-F-F+F+FF-F-F+F+FF+FF-F"}, 2, "F"),
    ("1.7b quadratic snowflake", "-F", {"F": "F+F-F-F+F"}, 4, "F"),
    ("1.8 islands and lakes", "F+F+F+F", {"F": "F+f-FF+F+FF+Ff+FF-f+FF-F-FF-Ff-FFF", "f": "ffffff"}, 2, "F"),
    ("1.9a", "F-F-F-F", {"F": "FF-F-F-F-F-F+F"}, 4, "F"),
    ("1.9b", "F-F-F-F", {"F": "FF-F-F-F-FF"}, 4, "F"),
    ("1.9c", "F-F-F-F", {"F": "FF-F+F-F-FF"}, 3, "F"),
    ("1.9d", "F-F-F-F", {"F": "FF-F--F-F"}, 4, "F"),
    ("1.9e", "F-F-F-F", {"F": "F-FF--F-F"}, 5, "F"),
    ("1.9f", "F-F-F-F", {"F": "F-F+F-F-F"}, 4, "F"),
    # F_l, F_r written L, R
    ("1.10a dragon", "L", {"L": "L+R+", "R": "-L-R"}, 10, "LR"),
    ("1.10b Sierpinski gasket", "R", {"L": "R+L+R", "R": "L-R-L"}, 6, "LR"),
    ("1.11a hexagonal Gosper", "L", {"L": "L+R++R-L--LL-R+", "R": "-L+RR++R+L--L-R"}, 4, "LR"),
    ("1.11b quadratic Gosper", "-R",
     {"L": "LL-R-R+L+L-R-RL+R+LLR-L+R+LL+R-LR-R-L+L+RR-",
      "R": "+LL-R-R+L+LR+L-RR-L-R+LRR-L-RL+L+R-R-L+L+RR"}, 2, "LR"),
    ("1.24a", "F", {"F": "F[+F]F[-F]F"}, 5, "F"),
    ("1.24b", "F", {"F": "F[+F]F[-F][F]"}, 5, "F"),
    ("1.24c", "F", {"F": "FF-[-F+F+F]+[+F-F-F]"}, 4, "F"),
    ("1.24d", "X", {"X": "F[+X]F[-X]+X", "F": "FF"}, 7, "F"),
    ("1.24e", "X", {"X": "F[+X][-X]FX", "F": "FF"}, 7, "F"),
    ("1.24f", "X", {"X": "F-[[X]+X]+F[+FX]-X", "F": "FF"}, 5, "F"),
    ("1.25 3D bush", "A",
     {"A": "[&FL!A]/////'[&FL!A]///////'[&FL!A]", "F": "S/////F", "S": "FL",
      "L": "['''^^{-f+f+f-|-f+f+f}]"}, 7, "F"),
]


@pytest.mark.parametrize("name,axiom,rules,n,draw", FIGURES, ids=[f[0] for f in FIGURES])
def test_figure_lengths_and_f_counts(name, axiom, rules, n, draw):
    want = parikh(axiom, rules, n)
    s = LSystem(axiom, rules).derive(n)
    assert len(s) == sum(want.values())
    n_f = sum(want.get(c, 0) for c in draw)
    assert sum(s.count(c) for c in draw) == n_f
    for c, k in want.items():
        assert s.count(c) == k, c


def test_known_closed_forms():
    # 1.10a: the dragon of order 10 has 2^10 edges; 1.10b: 3^6 edges
    assert sum(LSystem("L", {"L": "L+R+", "R": "-L-R"}).derive(10).count(c) for c in "LR") == 1024
    assert sum(LSystem("R", {"L": "R+L+R", "R": "L-R-L"}).derive(6).count(c) for c in "LR") == 729
    # 1.24a: F -> 5 F per step; |s_n| = 1 + 10 (5^n - 1) / 4
    s = LSystem("F", {"F": "F[+F]F[-F]F"}).derive(5)
    assert s.count("F") == 5 ** 5 and len(s) == 1 + 10 * (5 ** 5 - 1) // 4


def test_koch_islands_close_and_dragon_never_retraces():
    for axiom, rule, n in [("F-F-F-F", "F+FF-FF-F-F+F+FF-F-F+F+FF+FF-F", 2), ("F-F-F-F", "F-F+F+FF-F-F+F", 3)]:
        d = turtle_2d(LSystem(axiom, {"F": rule}).derive(n), angle=90)
        assert len(d.lines) == 1
        assert np.allclose(d.xy[0], d.xy[-1], atol=1e-9)
        assert d.n_segments == parikh(axiom, {"F": rule}, n)["F"]
    d = turtle_2d(LSystem("L", {"L": "L+R+", "R": "-L-R"}).derive(10), angle=90, draw="LR")
    pts = np.rint(d.xy).astype(int)
    assert np.allclose(d.xy, pts, atol=1e-9)
    edges = {tuple(sorted((tuple(a), tuple(b)))) for a, b in zip(pts[:-1], pts[1:])}
    assert len(edges) == 1024  # every unit edge drawn once


def test_hilbert_3d_visits_lattice_once():
    """ABOP figure 1.16 at n = 2: 63 unit segments through all 64 points of 4^3."""
    rules = {
        "A": "B-F+CFC+F-D&F^D-F+&&CFC+F+B//",
        "B": "A&F^CFB^F^D^^-F-D^|F^B|FC^F^A//",
        "C": "|D^|F^B-F+C^F^A&&FA&F^C+F+B^F^D//",
        "D": "|CFB-F+B|FA&F^A&&FB-F+B|FC//",
    }
    seg = turtle_3d(LSystem("A", rules).derive(2), angle=90)
    assert len(seg) == 63
    pts = np.vstack([seg.starts[:1], seg.ends])
    lattice = np.rint(pts).astype(int)
    assert np.allclose(pts, lattice, atol=1e-9)
    lattice -= lattice.min(axis=0)
    assert {tuple(p) for p in lattice} == {(i, j, k) for i in range(4) for j in range(4) for k in range(4)}
    assert np.allclose(np.linalg.norm(seg.ends - seg.starts, axis=1), 1.0)


def reference_context(axiom, rules, ignore, n):
    """Independent reference: bracketed context-sensitive rewriting
    (ABOP section 1.8) for single-symbol contexts; rules are
    (left or None, pred, right or None, successor)."""
    s = list(axiom)
    for _ in range(n):
        mate, stack = {}, []
        for i, c in enumerate(s):
            if c == "[":
                stack.append(i)
            elif c == "]":
                j = stack.pop()
                mate[i], mate[j] = j, i

        def left(i):
            i -= 1
            while i >= 0:
                if s[i] == "]":
                    i = mate[i] - 1
                elif s[i] == "[" or s[i] in ignore:
                    i -= 1
                else:
                    return s[i]
            return None

        def right(i):
            i += 1
            while i < len(s):
                if s[i] == "[":
                    i = mate[i] + 1
                elif s[i] in ignore:
                    i += 1
                elif s[i] == "]":
                    return None
                else:
                    return s[i]
            return None

        out = []
        for i, c in enumerate(s):
            for lc, p, rc, succ in rules:
                if p == c and (lc is None or left(i) == lc) and (rc is None or right(i) == rc):
                    out.extend(succ)
                    break
            else:
                out.append(c)
        s = out
    return "".join(s)


def test_context_sensitive_figure_1_31a():
    """Hogeweg and Hesper's signal-propagation plant, ABOP figure 1.31a."""
    table = [
        ("0", "0", "0", "0"), ("0", "0", "1", "1[+F1F1]"), ("0", "1", "0", "1"), ("0", "1", "1", "1"),
        ("1", "0", "0", "0"), ("1", "0", "1", "1F1"), ("1", "1", "0", "1"), ("1", "1", "1", "0"),
        (None, "+", None, "-"), (None, "-", None, "+"),
    ]
    lines = [f"{lc or '*'} < {p} > {rc or '*'} -> {succ}" for lc, p, rc, succ in table]
    sys_ = LSystem("F1F1F1", lines, ignore="+-F")
    for n in (1, 2, 5, 10, 30):
        want = reference_context("F1F1F1", table, "+-F", n)
        got = sys_.derive(n)
        assert str(got) == want, n
    s = sys_.derive(30)
    assert s.count("F") == want.count("F") and s.count("[") == want.count("[") > 0


def test_stochastic_figure_1_27_mean_length():
    """ABOP figure 1.27: F -(.33)-> F[+F]F[-F]F | -(.33)-> F[+F]F | -(.34)-> F[-F]F.

    Each F yields on average m = .33*5 + .34*3 + .33*3 = 3.66 F and
    l = .33*11 + .33*6 + .34*6 = 7.65 modules, so
    E|s_n| = 1 + (l - 1) * sum_{k<n} m^k.
    """
    rules = {"F": [("F[+F]F[-F]F", 0.33), ("F[+F]F", 0.33), ("F[-F]F", 0.34)]}
    n, n_seeds = 5, 1500
    m, ell = 0.33 * 5 + 0.33 * 3 + 0.34 * 3, 0.33 * 11 + 0.33 * 6 + 0.34 * 6
    expected = 1 + (ell - 1) * sum(m ** k for k in range(n))
    sys_ = LSystem("F", rules, seed=0)
    lengths = np.array([len(sys_.derive(n, seed=s, n_threads=1)) for s in range(n_seeds)], dtype=float)
    se = lengths.std(ddof=1) / np.sqrt(n_seeds)
    assert abs(lengths.mean() - expected) < 4 * se, (lengths.mean(), expected, se)
    # the F counts: E F_n = m^n
    f = np.array([sys_.derive(n, seed=s, n_threads=1).count("F") for s in range(300)], dtype=float)
    assert abs(f.mean() - m ** n) < 4 * f.std(ddof=1) / np.sqrt(len(f))
    # and the strings really vary
    assert len(set(lengths.tolist())) > 20


@pytest.mark.parametrize("name,angle", [("1.10b Sierpinski gasket", 60), ("1.11a hexagonal Gosper", 60),
                                        ("1.11b quadratic Gosper", 90)])
def test_edge_rewriting_curves_are_self_avoiding(name, angle):
    """These curves (ABOP 1.4.1) never revisit a vertex: a check of both the
    transcribed productions and the turtle."""
    _, axiom, rules, n, draw = next(f for f in FIGURES if f[0] == name)
    d = turtle_2d(LSystem(axiom, rules).derive(n), angle=angle, draw=draw)
    assert len(d.lines) == 1
    n_edges = parikh(axiom, rules, n)["L"] + parikh(axiom, rules, n)["R"]
    assert len(d.xy) == n_edges + 1
    assert len({tuple(p) for p in np.round(d.xy, 6)}) == n_edges + 1
    assert np.allclose(np.linalg.norm(np.diff(d.xy, axis=0), axis=1), 1.0)
