"""Random rule text never crashes, hangs or panics: every outcome is a
result or a ValueError (a Rust panic would surface as RuntimeError)."""

import random

from fractalgeo_rs.lsystem import LSystem, plant_mesh, turtle_2d

ALPHABET = list("AB F f+-[]()<>:,.*/^&!{}|$'x y0123456789.-") + ["->", "-(", ")->", " && ", "sqrt(", "x"]


def test_random_rules_give_results_or_value_errors():
    rng = random.Random(1234)
    outcomes = {"ok": 0, "ValueError": 0}
    for _ in range(3000):
        axiom = "".join(rng.choice(ALPHABET) for _ in range(rng.randint(0, 6)))
        def text(k):
            return "".join(rng.choice(ALPHABET) for _ in range(rng.randint(0, k)))

        # half of the rules have the shape "lhs -> successor"
        rules = [text(14) if rng.random() < 0.5 else f"{rng.choice('ABF')}{text(3)} -> {text(10)}"
                 for _ in range(rng.randint(0, 3))]
        try:
            s = LSystem(axiom, rules, seed=rng.randrange(100), max_length=5000).derive(rng.randint(0, 4))
            turtle_2d(s)
            plant_mesh(s, sides=3)
            outcomes["ok"] += 1
        except ValueError:
            outcomes["ValueError"] += 1
    assert outcomes["ok"] > 300 and outcomes["ValueError"] > 300, outcomes
