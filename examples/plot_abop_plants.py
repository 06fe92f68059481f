"""
Plants of The Algorithmic Beauty of Plants
==========================================

The six bracketed L-systems of figure 1.24 of Prusinkiewicz and Lindenmayer
(1990), derived by :class:`fractalgeo_rs.LSystem` and drawn by the 2D turtle
(:func:`fractalgeo_rs.lsystem.turtle_2d`): ``F`` draws a step, ``+`` and
``-`` turn by the angle, ``[`` and ``]`` push and pop the turtle's state.

Data: generated, no licence needed.
"""
import matplotlib.pyplot as plt
from matplotlib.collections import LineCollection

import fractalgeo_rs as fg
from fractalgeo_rs.lsystem import turtle_2d

plants = [
    ("a", "F", {"F": "F[+F]F[-F]F"}, 5, 25.7),
    ("b", "F", {"F": "F[+F]F[-F][F]"}, 5, 20.0),
    ("c", "F", {"F": "FF-[-F+F+F]+[+F-F-F]"}, 4, 22.5),
    ("d", "X", {"X": "F[+X]F[-X]+X", "F": "FF"}, 7, 20.0),
    ("e", "X", {"X": "F[+X][-X]FX", "F": "FF"}, 7, 25.7),
    ("f", "X", {"X": "F-[[X]+X]+F[+FX]-X", "F": "FF"}, 5, 22.5),
]
fig, axes = plt.subplots(1, 6, figsize=(15, 4.6), constrained_layout=True)
for ax, (tag, axiom, rules, n, angle) in zip(axes, plants):
    s = fg.LSystem(axiom, rules).derive(n)
    drawing = turtle_2d(s, angle=angle)
    ax.add_collection(LineCollection(drawing.lines, colors="darkgreen", linewidths=0.4))
    ax.autoscale()
    ax.set_aspect("equal")
    ax.set_axis_off()
    ax.set_title(f"1.24{tag}: n = {n}, {angle} deg\n{drawing.n_segments} segments", fontsize=9)
    print(f"1.24{tag}: {len(str(s))} symbols, {drawing.n_segments} segments")
plt.show()
