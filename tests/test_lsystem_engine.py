"""The rewriting engine: exact strings, parallel rewriting, contexts,
parameters, seeds, the text format and errors."""

import numpy as np
import pytest

import fractalgeo_rs
from fractalgeo_rs.lsystem import LString, LSystem


def test_seed_paper_eq23():
    algae = fractalgeo_rs.LSystem("b", {"b": "a", "a": "ab"})
    assert [str(algae.derive(n)) for n in range(6)] == ["b", "a", "ab", "aba", "abaab", "abaababa"]
    assert [str(s) for s in algae.generations(3)] == ["b", "a", "ab", "aba"]


def test_parallel_not_sequential_and_case_sensitive():
    s = LSystem("aA", ["a -> b", "b -> c", "A -> a"])
    assert str(s.derive(1)) == "ba"
    assert str(LSystem("Ff", {"F": "FF"}).derive(2)) == "FFFFf"
    assert str(LSystem("α", {"α": "αβ", "β": "γ"}).derive(3)) == "αβγγ"  # any Unicode symbol


def test_parametric_abop_page_43():
    # hand-derived in ABOP section 1.10
    s = LSystem("B(2)A(4,4)", ["A(x,y): y <= 3 -> A(x*2, x+y)", "A(x,y): y > 3 -> B(x)A(x/y, 0)",
                               "B(x): x < 1 -> C", "B(x): x >= 1 -> B(x-1)"])
    want = ["B(2)A(4,4)", "B(1)B(4)A(1,0)", "B(0)B(3)A(2,1)", "CB(2)A(4,3)", "CB(1)A(8,7)"]
    assert [str(s.derive(n)) for n in range(5)] == want
    vals, off = s.derive(4).parameters()
    assert vals.tolist() == [1.0, 8.0, 7.0] and off.tolist() == [0, 0, 1, 3]


def test_expressions_functions_and_power():
    s = LSystem("A(2)", ["A(x) : x < 100 && !(x == 3) -> A(x^2 + sqrt(16) - 4)B(max(x, 5) % 3)"])
    assert str(s.derive(1)) == "A(4)B(2)"
    assert str(s.derive(2)) == "A(16)B(2)B(2)"


def test_contexts_follow_abop_1_8():
    s = LSystem("ABC[DE][SG[HI[JK]L]MNO]", ["BC < S > G[H]M -> X"])
    assert str(s.derive(1)) == "ABC[DE][XG[HI[JK]L]MNO]"
    # signal propagation along a branching axis, ignoring turns
    s = LSystem("baaa[+a]a", ["b < a -> b", "b -> a"], ignore="+")
    want = ["baaa[+a]a", "abaa[+a]a", "aaba[+a]a", "aaab[+a]a", "aaaa[+b]b", "aaaa[+a]a"]
    assert [str(s.derive(n)) for n in range(6)] == want


def test_same_seed_same_strings_any_threads():
    rules = {"F": [("F[+F]F[-F]F", 1), ("F[+F]F", 1), ("F[-F]F", 1)]}
    a = LSystem("F", rules, seed=5).derive(9, n_threads=1)
    b = LSystem("F", rules, seed=5).derive(9, n_threads=2)
    c = LSystem("F", rules, seed=5).derive(9, n_threads=7)
    assert len(a) > 100_000 and a == b == c
    assert LSystem("F", rules, seed=6).derive(9) != a
    s = LSystem("F", rules)
    assert s.derive(6) == s.derive(6)  # a drawn seed is kept


def test_text_format_and_file(tmp_path):
    text = """
    # ABOP figure 1.24d
    axiom: X
    n: 7
    angle: 20
    X -> F[+X]F[-X]+X
    F -> FF   # doubling
    """
    s = LSystem.from_string(text)
    assert s.defaults == {"n": "7", "angle": "20"}
    assert str(s.derive(1)) == "F[+X]F[-X]+X"
    p = tmp_path / "plant.txt"
    p.write_text("axiom: F\nseed: 3\nF -(1)-> F[+F]F\nF -(3)-> F[-F]F  # three times as likely\n")
    st = LSystem.from_file(p)
    assert st.seed == 3 and st.is_stochastic
    s1 = st.derive(1)
    assert str(s1) in ("F[+F]F", "F[-F]F")
    counts = [str(LSystem.from_file(p, seed=k).derive(1)) for k in range(400)]
    assert 0.65 < counts.count("F[-F]F") / 400 < 0.85
    assert LSystem.from_string("axiom: a\nignore: +\nb < a -> c\n").ignore == "+"


def test_parametric_turtle_total_length():
    """A(s) -> F(s)[+A(s/2)][-A(s/2)]: step k draws 2^k segments of length
    2^-k, so after n steps the drawn length is exactly n."""
    from fractalgeo_rs.lsystem import turtle_2d
    s = LSystem("A(1)", ["A(s) -> F(s)[+A(s/2)][-A(s/2)]"]).derive(8)
    d = turtle_2d(s, angle=30)
    length = sum(np.linalg.norm(np.diff(line, axis=0), axis=1).sum() for line in d.lines)
    assert length == pytest.approx(8.0, abs=1e-12)
    assert s.count("F") == 2 ** 8 - 1


def test_lstring_parse():
    s = LString.parse("F(1)[+A(2, 3*2)]")
    assert str(s) == "F(1)[+A(2,6)]" and len(s) == 5 and s.count("A") == 1 and s.symbols == "F[+A]"


@pytest.mark.parametrize(
    "axiom,rules,kw,param",
    [
        ("F[", {"F": "F"}, {}, "axiom"),
        ("F", {"F": "F[+F"}, {}, "rules"),
        ("F", {"F": "F]+F["}, {}, "rules"),
        ("A(1)", ["A(x) -> A(y)"], {}, "rules"),
        ("A(1)", ["A(x): z > 0 -> A(x)"], {}, "rules"),
        ("F", ["F => FF"], {}, "rules"),
        ("F", ["F G -> FF"], {}, "rules"),
        ("F", ["F -> F(1"], {}, "rules"),
        ("F", {"F": [("FF", 0), ("F", 0)]}, {}, "rules"),
        ("F", {"F": [("FF", -1), ("F", 2)]}, {}, "rules"),
        ("F", ["F -> FF", "F -> F"], {}, "rules"),
        ("A(x)", [], {}, "axiom"),
        ("", [], {}, "axiom"),
        ("F", [], {"ignore": "[+"}, "ignore"),
        ("F", [], {"max_length": 0}, "max_length"),
    ],
)
def test_bad_input_names_the_parameter(axiom, rules, kw, param):
    with pytest.raises(ValueError, match=f"^{param}:"):
        LSystem(axiom, rules, **kw)


def test_runaway_growth_is_a_value_error():
    s = LSystem("F", {"F": "FF"}, max_length=10_000)
    assert len(s.derive(13)) == 8192
    # counted before expanding: a MemoryError that is a ValueError, naming n
    with pytest.raises(MemoryError, match=r"^n: 14 derivation steps give exactly 16384 modules .*max_length=10000"):
        s.derive(14)
    with pytest.raises(ValueError, match=r"^n: 40 derivation steps give more than 3.4e\+38 modules"):
        LSystem("F", {"F": "F" * 50}).derive(40)  # default limit, no hang
    # a condition hides the growth from the count (lower bound 1): the
    # expansion itself stops at max_length
    cond = LSystem("A(1)", ["A(x): x > 0 -> A(x)A(x)"], max_length=1000)
    assert cond.length_bounds(12) == (1, 4096) and len(cond.derive(9)) == 512
    with pytest.raises(ValueError, match="^max_length: derivation step 10 "):
        cond.derive(12)
    with pytest.raises(ValueError, match="^n:"):
        LSystem("F", {"F": "F"}).derive(10**7)  # would never end otherwise
    with pytest.raises(ValueError, match="^rules:.*nesting"):
        LSystem("A(1)", ["A(x) -> A(" + "(" * 5000 + "x" + ")" * 5000 + ")"])
    with pytest.raises(ValueError, match="^rules:.*non-finite"):
        LSystem("A(1)", ["A(x) -> A(x/0)"]).derive(1)


def test_type_errors():
    with pytest.raises(TypeError, match="^axiom:"):
        LSystem(1, {})
    with pytest.raises(TypeError, match="^rules:"):
        LSystem("F", 5)
    with pytest.raises(TypeError, match="^rules:"):
        LSystem("F", {"F": [("F", "heavy")]})
    with pytest.raises(ValueError, match="^n:"):
        LSystem("F", {}).derive(-1)
    with pytest.raises(ValueError, match="^text:"):
        LSystem.from_string("F -> FF")


def test_length_is_counted_before_expanding():
    import time

    from fractalgeo_rs._validation import MemoryLimitError

    ten = LSystem("F", {"F": "FFFFFFFFFF"})
    t0 = time.perf_counter()
    with pytest.raises(MemoryLimitError) as e:
        ten.derive(30)
    assert time.perf_counter() - t0 < 0.5
    msg = str(e.value)
    assert msg.startswith("n: 30 derivation steps give exactly 1e+30 modules"), msg
    assert "max_length=100000000" in msg
    assert ten.length_bounds(30) == (10**30, 10**30)
    # within max_length but above the memory limit: the memory policy's message
    big = LSystem("F", {"F": "FF"}, max_length=2**62)
    with pytest.raises(MemoryLimitError, match=r"^n: needs about .* for n=60 derivation steps \(exactly"):
        big.derive(60)
    # Koch snowflake 7 * 4**n, dragon 2**(n+2) - 2: closed forms = real lengths
    koch = LSystem("F++F++F", {"F": "F-F++F-F"})
    dragon = LSystem("FX", {"X": "X+YF+", "Y": "-FX-Y"})
    for n in range(7):
        assert koch.length_bounds(n) == (7 * 4**n,) * 2 == (len(koch.derive(n)),) * 2
        assert dragon.length_bounds(n) == (2 ** (n + 2) - 2,) * 2 == (len(dragon.derive(n)),) * 2
    # stochastic: bounds from the smallest and largest alternative
    st = LSystem("F", ["F -(1)-> FF", "F -(1)-> F", "F -(1)-> F[+F]"])
    lo, hi = st.length_bounds(5)
    assert (lo, hi) == (1, 2**5 + 3 * (2**5 - 1))
    assert all(lo <= len(st.derive(5, seed=k)) <= hi for k in range(10))
    with pytest.raises(ValueError, match="^n:"):
        ten.length_bounds(10**7)
