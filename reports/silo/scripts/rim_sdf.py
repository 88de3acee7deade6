# Estimate how trilinear interpolation of the silo wall's distance field (cell h) moves the
# place where a grain of radius a touches the orifice rim, against the exact distance.
# Meridian section of the wall near the orifice: parallelogram with the rim at (r0, 0),
# inner cone up-outward at 45 deg, lip ring z = 0 from r0 to r0 + t.
import math
r0, t, a = 0.02, 0.01, 0.002
def seg(p, q, x):
    dx, dz = q[0]-p[0], q[1]-p[1]; u = ((x[0]-p[0])*dx + (x[1]-p[1])*dz)/(dx*dx+dz*dz)
    u = max(0, min(1, u)); return math.hypot(x[0]-p[0]-u*dx, x[1]-p[1]-u*dz)
A, B, C, D = (r0, 0), (r0+0.05, 0.05), (r0+t+0.05, 0.05), (r0+t, 0)
def dist(x, y, z):  # unsigned distance to the wall's surface, outside the solid (grains)
    r = math.hypot(x, y)
    return min(seg(A, B, (r, z)), seg(A, D, (r, z)), seg(D, C, (r, z)))
def tri(x, y, z, h, o):
    i, j, k = [math.floor((c - oc)/h) for c, oc in zip((x, y, z), o)]
    fx, fy, fz = [(c - oc)/h - n for c, oc, n in zip((x, y, z), o, (i, j, k))]
    v = 0
    for di in (0, 1):
        for dj in (0, 1):
            for dk in (0, 1):
                w = (fx if di else 1-fx)*(fy if dj else 1-fy)*(fz if dk else 1-fz)
                v += w*dist(o[0]+(i+di)*h, o[1]+(j+dj)*h, o[2]+(k+dk)*h)
    return v
def touch_r(z, h, o, ang):  # radius at which a grain centre at height z first touches, coming from the axis
    f = (lambda r: dist(r*math.cos(ang), r*math.sin(ang), z)) if h is None else (lambda r: tri(r*math.cos(ang), r*math.sin(ang), z, h, o))
    lo, hi = 0.0, r0 + 0.003
    if f(hi) > a: return None
    for _ in range(50):
        m = (lo+hi)/2
        if f(m) > a: lo = m
        else: hi = m
    return lo
import random
random.seed(1)
for h in (1.5e-3, 0.75e-3):
    shifts = []
    for s in range(40):
        o = (random.uniform(0, h), random.uniform(0, h), random.uniform(0, h))
        ang = random.uniform(0, math.pi/2)
        for z in (-0.001, 0.0, 0.001, 0.002):
            e, g = touch_r(z, None, o, ang), touch_r(z, h, o, ang)
            if e and g: shifts.append(g - e)
    m = sum(shifts)/len(shifts)
    print(f"cell {h*1e3:.2f} mm: touch radius shift at the rim, mean {m*1e3:+.3f} mm, min {min(shifts)*1e3:+.3f}, max {max(shifts)*1e3:+.3f} (n {len(shifts)})")
