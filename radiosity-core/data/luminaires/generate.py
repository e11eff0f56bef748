#!/usr/bin/env python3
"""Writes the luminaire files of this folder (run it here: python3 generate.py).

Each distribution is a formula sampled on a table; the declared lumens are the table's flux, the
integral over the sphere of its bilinear interpolation (as radiosity_core::photometry computes it),
except for the CIE 171 cases, whose declared lumens are the exact values of the formula.
"""
import math

def profile_integral(gamma, row):
    s = 0.0
    for k in range(len(gamma) - 1):
        a, b = math.radians(gamma[k]), math.radians(gamma[k + 1])
        d = b - a
        s0 = math.cos(a) - math.cos(b)
        s1 = ((math.cos(a) - math.cos(b)) * (-a) + (-b * math.cos(b) + math.sin(b) + a * math.cos(a) - math.sin(a))) / d
        s += row[k] * (s0 - s1) + row[k + 1] * s1
    return s

def flux(c, gamma, table):
    p = [profile_integral(gamma, r) for r in table]
    if len(c) == 1:
        return 2 * math.pi * p[0]
    s = sum(math.radians(c[i + 1] - c[i]) * 0.5 * (p[i] + p[i + 1]) for i in range(len(c) - 1))
    if c[-1] == 90:
        return 4 * s
    if c[-1] == 180:
        return 2 * s
    return s + math.radians(360 - c[-1]) * 0.5 * (p[-1] + p[0])

def fmt(v):
    return f"{v:.6f}".rstrip("0").rstrip(".") if v != 0 else "0"

def lines_of(values, per_line=10):
    return [" ".join(fmt(v) for v in values[i:i + per_line]) for i in range(0, len(values), per_line)]

def write_ies(name, version, keywords, lumens, c, gamma, table, opening="0 0 0"):
    out = [version] if version else []
    out += [f"[{k}] {v}" for k, v in keywords]
    out.append("TILT=NONE")
    out.append(f"1 {fmt(lumens)} 1 {len(gamma)} {len(c)} 1 2 {opening}")
    out.append("1 1 0")
    out += lines_of(gamma)
    out += lines_of(c)
    for row in table:
        out += lines_of(row)
    with open(name, "w") as f:
        f.write("\r\n".join(out) + "\r\n")

def write_ldt(name, title, lumens, c, gamma, table):
    out = ["radiosity (generated, MIT OR Apache-2.0)", "1", "0", str(len(c)), "15", str(len(gamma)), "5",
           "generated", title, "1", name, "2026", "100", "100", "50", "80", "80", "0", "0", "0", "0",
           "100", "100", "1", "0", "1", "1", "LED", fmt(lumens), "3000", "1B", "20"]
    out += ["0"] * 10
    out += [fmt(x) for x in c]
    out += [fmt(g) for g in gamma]
    for row in table:
        out += [f"{v * 1000.0 / lumens:.6f}" for v in row]
    with open(name, "w") as f:
        f.write("\r\n".join(out) + "\r\n")

# CIE 171:2006 5.2: Lambertian point source I(γ) = 1000 cos γ cd, 0 above the horizontal.
g = list(range(0, 91, 5))
write_ies("lambert_1000cd.ies", "IESNA:LM-63-2002",
          [("TEST", "CIE 171 5.2 Lambertian point source"), ("MANUFAC", "radiosity (generated)"),
           ("_FORMULA", "I = 1000 cos(gamma) cd, gamma 0-90; 0 beyond; declared lumens pi*1000")],
          1000 * math.pi, [0], g, [[round(1000 * math.cos(math.radians(x)), 6) for x in g]])

# CIE 171:2006 5.4: isotropic point source of 10 000 lm.
g = list(range(0, 181, 10))
write_ies("isotropic_10000lm.ies", "IESNA:LM-63-2002",
          [("TEST", "CIE 171 5.4 isotropic point source"), ("MANUFAC", "radiosity (generated)"),
           ("_FORMULA", "I = 10000/(4 pi) cd in every direction")],
          10000, [0], g, [[round(10000 / (4 * math.pi), 6)] * len(g)])

# An asymmetric downlight (a wall-washing downlight): I = 2000 cos²γ (1 + 0.5 sin γ cos C), γ 0-90.
c = list(range(0, 360, 15))
g = list(range(0, 91, 5))
table = [[round(2000 * math.cos(math.radians(y)) ** 2 * (1 + 0.5 * math.sin(math.radians(y)) * math.cos(math.radians(x))), 1)
          for y in g] for x in c]
lm = round(flux(c, g, table))
write_ies("downlight_asymmetric.ies", "IESNA:LM-63-2002",
          [("TEST", "asymmetric downlight"), ("MANUFAC", "radiosity (generated)"),
           ("_FORMULA", "I = 2000 cos^2(gamma) (1 + 0.5 sin(gamma) cos(C)) cd, gamma 0-90"),
           ("_SAME_AS", "downlight_asymmetric.ldt")], lm, c, g, table, "0.08 0.08 0")
write_ldt("downlight_asymmetric.ldt", "asymmetric downlight", lm, c, g, table)

# The README's example: a linear luminaire, quadrant symmetric, mostly down with some uplight.
c = [0, 45, 90]
g = list(range(0, 181, 15))
def linear(x, y):
    cg = math.cos(math.radians(y))
    return 400 * cg * (0.6 + 0.4 * math.cos(math.radians(x)) ** 2) if y <= 90 else 80 * -cg
table = [[round(linear(x, y), 1) for y in g] for x in c]
lm = round(flux(c, g, table))
write_ies("linear_example.ies", "IESNA:LM-63-1995",
          [("TEST", "linear luminaire example"), ("MANUFAC", "radiosity (generated)")], lm, c, g, table)
