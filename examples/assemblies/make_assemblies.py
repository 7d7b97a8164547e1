#!/usr/bin/env python3
"""Writes the bundled assemblies of this folder (blocks only; `crr assemble` finds the joints):
arch.toml, wall.toml, facade.toml, trilithon.toml and segmental_arch.toml. Run from this folder: python3 make_assemblies.py"""
import math


def box(name, x, z, depth, density, y=0.0):
    (x0, x1), (z0, z1) = x, z
    return (
        f'[[body]]\nname = "{name}"\ndensity = {density!r}\n'
        f"box = {{ center = [{(x0 + x1) / 2!r}, {y!r}, {(z0 + z1) / 2!r}], "
        f"size = [{x1 - x0!r}, {depth!r}, {z1 - z0!r}] }}\n"
    )


def arch(n=9, r_in=2.0, r_out=2.5, depth=1.0, density=2200.0):
    out = [
        f"# A semicircular arch of {n} voussoirs cut by radial joints: intrados radius {r_in} m, extrados",
        f"# {r_out} m (t/R = {(r_out - r_in) / ((r_in + r_out) / 2):.3f} on the centre line, about twice Heyman's least",
        "# thickness 0.1075 R), 1 m deep along y, stone of 2200 kg/m^3, springing on the ground",
        "# (z = 0). Blocks only: `crr assemble --all-contacts` finds its 10 joints (two beds on the",
        "# ground and eight inclined joints). Written by make_assemblies.py.",
        'name = "arch_of_voussoirs"',
        "gravity = 9.81",
        "",
    ]
    for i in range(n):
        a0, a1 = math.pi * i / n, math.pi * (i + 1) / n
        out.append(
            f'[[body]]\nname = "v{i + 1}"\ndensity = {density!r}\n'
            f"annular_sector = {{ center = [0.0, 0.0, 0.0], axis = [0.0, -1.0, 0.0], start = [1.0, 0.0, 0.0], "
            f"inner_radius = {r_in!r}, outer_radius = {r_out!r}, thickness = {depth!r}, "
            f"from_angle = {a0!r}, to_angle = {a1!r} }}\n"
        )
    out.append(
        "# The bundled record (PGA 0.25 g) scaled to 0.3875 g, 6 % above the arch's static multiplier\n"
        "# 0.366 along x.\n"
        "[ground_motion]\n"
        'x = { record = { file = "../records/synthetic.AT2", format = "peer-at2" }, scale = 1.55 }\n'
    )
    return "\n".join(out)


def segmental_arch(n=7, r_in=3.0, r_out=3.4, springing=30.0, depth=1.0, density=2200.0, scale=None):
    alpha = math.radians(springing)
    beyond = math.radians(20.0)
    out = [
        f"# A segmental arch of {n} voussoirs cut by radial joints between two skewback stones of its",
        f"# abutments: intrados radius {r_in} m, extrados {r_out} m, springing at {springing:g} degrees above the",
        f"# horizontal (span {2 * r_in * math.cos(alpha):.3f} m at the intrados), 1 m deep along y, stone of",
        f"# {density:g} kg/m^3. The skewbacks (annular sectors 20 degrees beyond each springing) are part",
        "# of the abutments, which move with the ground: `fixed` names them, so `crr assemble",
        f"# --all-contacts` finds {n + 1} joints, the two springings resting on the ground. Written by",
        "# make_assemblies.py.",
        'name = "segmental_arch"',
        "gravity = 9.81",
        'fixed = ["skewback_right", "skewback_left"]',
        "",
    ]

    def sector(name, a0, a1):
        return (
            f'[[body]]\nname = "{name}"\ndensity = {density!r}\n'
            f"annular_sector = {{ center = [0.0, 0.0, 0.0], axis = [0.0, -1.0, 0.0], start = [1.0, 0.0, 0.0], "
            f"inner_radius = {r_in!r}, outer_radius = {r_out!r}, thickness = {depth!r}, "
            f"from_angle = {a0!r}, to_angle = {a1!r} }}\n"
        )

    at = [alpha + (math.pi - 2 * alpha) * j / n for j in range(n)] + [math.pi - alpha]
    out.append(sector("skewback_right", alpha - beyond, alpha))
    for i in range(n):
        out.append(sector(f"v{i + 1}", at[i], at[i + 1]))
    out.append(sector("skewback_left", math.pi - alpha, math.pi - alpha + beyond))
    if scale is not None:
        out.append(scale)
    return "\n".join(out)


def courses_of(courses, blocks, l, hb, opening=None, lintel=None):
    """Running bond: even courses `blocks` whole blocks from -B/2 to B/2, odd courses a half block,
    blocks - 1 whole ones and a half block. `opening` = (x0, x1, courses) leaves the courses below
    it open between x0 and x1 (blocks cut at its jambs); `lintel` = (x0, x1, course) replaces that
    course's blocks between x0 and x1 by one stone."""
    x0 = -blocks * l / 2.0
    rows = []
    for c in range(courses):
        if c % 2 == 0:
            cuts = [x0 + l * i for i in range(blocks + 1)]
        else:
            cuts = [x0] + [x0 + l * (0.5 + i) for i in range(blocks)] + [x0 + l * blocks]
        pieces = list(zip(cuts, cuts[1:]))
        if opening and c < opening[2]:
            kept = []
            for a, b in pieces:
                if b <= opening[0] + 1e-12 or a >= opening[1] - 1e-12:
                    kept.append((a, b))
                else:
                    if a < opening[0]:
                        kept.append((a, opening[0]))
                    if b > opening[1]:
                        kept.append((opening[1], b))
            pieces = kept
        if lintel and c == lintel[2]:
            pieces = [p for p in pieces if p[1] <= lintel[0] + 1e-12 or p[0] >= lintel[1] - 1e-12]
            pieces.append((lintel[0], lintel[1]))
            pieces.sort()
        rows.append([((a, b), (c * hb, (c + 1) * hb)) for a, b in pieces])
    return rows


def wall_text(name, header, rows, depth, density, tail=""):
    out = header + [f'name = "{name}"', "gravity = 9.81", ""]
    for c, row in enumerate(rows):
        for i, (x, z) in enumerate(row):
            out.append(box(f"c{c}_b{i}", x, z, depth, density))
    return "\n".join(out) + tail


def wall():
    rows = courses_of(8, 5, 0.6, 0.25)
    header = [
        "# A planar wall in running bond: 8 courses of 0.25 m, 5 blocks of 0.6 x 0.3 x 0.25 m per",
        "# course, odd courses offset by half a block with half blocks at their ends (3 m x 2 m in",
        "# all), dry joints, 2000 kg/m^3. Blocks only: `crr assemble --planar` makes every bed joint",
        "# a hinge about y (head joints are reported, not interfaces). Written by make_assemblies.py.",
    ]
    return wall_text("running_bond_wall", header, rows, 0.3, 2000.0)


def facade():
    rows = courses_of(7, 9, 0.5, 0.3, opening=(-0.75, 0.75, 4), lintel=(-1.25, 1.25, 4))
    header = [
        "# A facade with a door: a running-bond wall of 7 courses of 0.3 m, 9 blocks of 0.5 x 0.4 x",
        "# 0.3 m per course (4.5 m x 2.1 m), with an opening 1.5 m wide through the 4 lowest courses",
        "# (the blocks at its jambs cut short) under a lintel stone 2.5 m long in the fifth course;",
        "# 2000 kg/m^3. Blocks only: `crr assemble --planar`. Written by make_assemblies.py.",
    ]
    return wall_text("facade_with_door", header, rows, 0.4, 2000.0)


def trilithon():
    header = [
        "# The trilithon of examples/models/trilithon.toml as three stones: two posts 0.5 x 0.5 x",
        "# 4.0 m, 3 m apart, under an architrave 3.5 x 0.5 x 0.6 m, 2500 kg/m^3.",
        "# Blocks only: `crr assemble --planar` gives the model's four hinges. Written by",
        "# make_assemblies.py.",
        'name = "trilithon_of_stones"',
        "gravity = 9.81",
        "",
    ]
    bodies = [
        box("column_left", (-1.75, -1.25), (0.0, 4.0), 0.5, 2500.0),
        box("column_right", (1.25, 1.75), (0.0, 4.0), 0.5, 2500.0),
        box("architrave", (-1.75, 1.75), (4.0, 4.6), 0.5, 2500.0),
    ]
    tail = (
        "\n# The bundled record (PGA 0.25 g) scaled to 0.15 g, above the frame's multiplier b/h = 0.125.\n"
        "[ground_motion]\n"
        'x = { record = { file = "../records/synthetic.AT2", format = "peer-at2" }, scale = 0.6 }\n'
    )
    return "\n".join(header) + "\n".join(bodies) + tail


SEGMENTAL_ARCH_MOTION = (
    "# The bundled record (PGA 0.25 g) scaled to 0.8 g, 6 % above the arch's static multiplier\n"
    "# 0.754 along x.\n"
    "[ground_motion]\n"
    'x = { record = { file = "../records/synthetic.AT2", format = "peer-at2" }, scale = 3.2 }\n'
)

if __name__ == "__main__":
    for name, text in [
        ("arch", arch()),
        ("wall", wall()),
        ("facade", facade()),
        ("trilithon", trilithon()),
        ("segmental_arch", segmental_arch(scale=SEGMENTAL_ARCH_MOTION)),
    ]:
        with open(f"{name}.toml", "w") as f:
            f.write(text)
