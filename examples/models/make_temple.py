"""Writes examples/models/temple.toml, a bay of a Greek temple peristyle (python3 make_temple.py).

2 rows x 3 columns; each column: 3 drums (16-gon prisms) and a capital (square abacus); one
entablature (the architraves of the bay, clamped into a rigid ring) on the six capitals. Every
joint is a rectangular rocking base; the entablature's seats on five capitals close the loops
and may twist on their pivot corner (twist = true): the loops then move to all orders.
"""
import math
import pathlib

S = 2.6          # column spacing along x (axis to axis), m
W = 2.6          # spacing of the two rows along y, m
R = 0.45         # drum radius (circumradius of the 16-gon), m
H_DRUM = 1.3     # drum height, m
N_DRUMS = 3
A = 1.1          # abacus side, m
H_CAP = 0.45     # capital height, m
H_ENT = 0.7      # entablature (architrave) height, m; its width is the abacus side
GAP = 0.01       # the cut that makes the ring's plan a simple polygon, m
RHO = 2500.0     # marble, kg/m^3
a = R / math.sqrt(2)  # half-side of the square bed inscribed in the drum

xs = [-S, 0.0, S]
ys = [-W / 2, W / 2]
z_shaft = N_DRUMS * H_DRUM
z_cap_top = z_shaft + H_CAP
h = A / 2


def f(v):
    return repr(float(v))


def pt(x, y, z):
    return f"[{f(x)}, {f(y)}, {f(z)}]"


def square(cx, cy, half, z):
    """Bed corners, first edge along +x (tilt .1 about x, .2 about y)."""
    c = [(cx - half, cy - half), (cx + half, cy - half), (cx + half, cy + half), (cx - half, cy + half)]
    return "[" + ", ".join(pt(x, y, z) for x, y in c) + "]"


def polygon16(cx, cy, z):
    return "[" + ", ".join(
        pt(cx + R * math.cos(2 * math.pi * k / 16), cy + R * math.sin(2 * math.pi * k / 16), z)
        for k in range(16)) + "]"


HEADER = f"""# A bay of a Greek temple peristyle: 2 rows x 3 columns (spacing {S} m along x, {W} m along
# y), each column 3 drums (16-gon prisms, radius {R} m, {H_DRUM} m high) and a capital (abacus
# {A} x {A} m, {H_CAP} m high); on the six capitals one entablature {H_ENT} m high and {A} m wide:
# the architraves of the bay along x and y, clamped into a rigid ring (Greek builders joined the
# architrave blocks with iron clamps; the ring's plan is cut by {GAP} m at x = -{S + h:.2f} m so
# that it is a simple polygon). Marble, {RHO} kg/m^3. Written by `python3 make_temple.py`.
#
# Every joint is a rectangular rocking base, its bed the square inscribed in the drum
# (half-side b = {a:.6f} m) or the abacus under the entablature; tilt .1 turns about x (rocking
# in y), .2 about y (rocking in x). The entablature rests on c11 (tree) and closes five loops on
# the other capitals, in both directions; those seats may twist on their pivot corner
# (twist = true), so the loops move to all orders: `crr check` gives DOF(2) = 35 at rest and
# after a finite step, 15 closure rows of rank 15.
#
# Static multiplier (`crr check`): lambda = 0.163178 along +-x, the frame rule: a frame
# of rocking columns under a rigid entablature uplifts at the columns' own g tan(alpha)
# (Makris & Vassiliou 2013), tan(alpha) = 2b / (3 H_drum) = {2 * a / (N_DRUMS * H_DRUM):.6f}
# for the drum shaft, whatever the entablature's weight; 0.162905 along +-y, where the back row
# rocks with its capitals and the entablature tilts on their abaci.
#
# Ground motion: the bundled synthetic record along x and its second component (another seed of
# the same procedure) along y, PGA 0.25 g each.
"""


def main():
    bodies, ifaces = [], []
    for j, x in enumerate(xs):
        for i, y in enumerate(ys):
            c = f"c{i + 1}{j + 1}"
            for d in range(N_DRUMS):
                z0 = d * H_DRUM
                bodies.append(f'[[body]]\nname = "{c}_drum_{d + 1}"\ndensity = {RHO}\n'
                              f'prism = {{ polygon = {polygon16(x, y, z0)}, extrude = [0.0, 0.0, {f(H_DRUM)}] }}\n')
                parent = "ground" if d == 0 else f"{c}_drum_{d}"
                ifaces.append(f'[[interface]]\nname = "{c}_bed_{d + 1}"\nparent = "{parent}"\n'
                              f'child = "{c}_drum_{d + 1}"\nrocking_base = {{ corners = {square(x, y, a, z0)} }}\n')
            bodies.append(f'[[body]]\nname = "{c}_capital"\ndensity = {RHO}\n'
                          f'box = {{ center = {pt(x, y, z_shaft + H_CAP / 2)}, size = [{f(A)}, {f(A)}, {f(H_CAP)}] }}\n')
            ifaces.append(f'[[interface]]\nname = "{c}_neck"\nparent = "{c}_drum_{N_DRUMS}"\n'
                          f'child = "{c}_capital"\nrocking_base = {{ corners = {square(x, y, a, z_shaft)} }}\n')
    x0, x1 = xs[0] - h, xs[-1] + h
    y0, y1 = ys[0] - h, ys[-1] + h
    ring = [(x0, y0), (x1, y0), (x1, y1), (x0, y1), (x0, GAP / 2), (x0 + A, GAP / 2),
            (x0 + A, y1 - A), (x1 - A, y1 - A), (x1 - A, y0 + A), (x0 + A, y0 + A),
            (x0 + A, -GAP / 2), (x0, -GAP / 2)]
    poly = "[" + ", ".join(pt(x, y, z_cap_top) for x, y in ring) + "]"
    bodies.append(f'[[body]]\nname = "entablature"\ndensity = {RHO}\n'
                  f'prism = {{ polygon = {poly}, extrude = [0.0, 0.0, {f(H_ENT)}] }}\n')
    for j, x in enumerate(xs):
        for i, y in enumerate(ys):
            c = f"c{i + 1}{j + 1}"
            twist = "" if c == "c11" else ", twist = true"
            ifaces.append(f'[[interface]]\nname = "entablature_on_{c}"\nparent = "{c}_capital"\n'
                          f'child = "entablature"\nrocking_base = {{ corners = {square(x, y, h, z_cap_top)}{twist} }}\n')
    tail = """[ground_motion]
x = { record = { file = "../records/synthetic.AT2", format = "peer-at2" } }
y = { record = { file = "../records/synthetic_y.AT2", format = "peer-at2" } }

[analysis]
duration = 6.0
# The bay rocks by 1e-6 to 1e-4 rad: snapping joints within the default simultaneity (1e-8 rad)
# of their seats to exactly 0 under the bay's 74 t of stone moves 6.7 % of the energy the
# impacts dissipate before the run stops, which the run warns about; within 1e-11 rad the
# snaps move 2.4e-5 of it.
simultaneity = 1e-11
"""
    text = HEADER + '\nname = "temple"\ngravity = 9.81\n\n' + "\n".join(bodies) + "\n" + "\n".join(ifaces) + "\n" + tail
    out = pathlib.Path(__file__).with_name("temple.toml")
    out.write_text(text)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
