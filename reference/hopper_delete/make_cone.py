"""A conical hopper shell as a closed ASCII STL: inner radius r0 at z=0 (the orifice) widening
at `half_angle` from the vertical to height h, wall thickness t, outward normals."""
import math, sys
r0, h, half_angle, t, n, rings = 0.016, 0.09, 30.0, 0.005, 64, 9
a = math.radians(half_angle)
ri = lambda z: r0 + z * math.tan(a)
ro = lambda z: ri(z) + t / math.cos(a)
zs = [h * k / rings for k in range(rings + 1)]
def p(r, th, z): return (r * math.cos(th), r * math.sin(th), z)
tris = []
def quad(A, B, C, D, want):
    for tri in ((A, B, C), (A, C, D)):
        u = [tri[1][i] - tri[0][i] for i in range(3)]
        v = [tri[2][i] - tri[0][i] for i in range(3)]
        nrm = (u[1]*v[2]-u[2]*v[1], u[2]*v[0]-u[0]*v[2], u[0]*v[1]-u[1]*v[0])
        c = [sum(q[i] for q in tri) / 3 for i in range(3)]
        w = want(c)
        if sum(nrm[i]*w[i] for i in range(3)) < 0:
            tri = (tri[0], tri[2], tri[1]); nrm = tuple(-x for x in nrm)
        l = math.sqrt(sum(x*x for x in nrm)); tris.append((tuple(x/l for x in nrm), tri))
for i in range(n):
    t0, t1 = 2*math.pi*i/n, 2*math.pi*(i+1)/n
    for k in range(rings):
        z0, z1 = zs[k], zs[k+1]
        # inner face: normal toward the axis
        quad(p(ri(z0),t0,z0), p(ri(z0),t1,z0), p(ri(z1),t1,z1), p(ri(z1),t0,z1), lambda c: (-c[0], -c[1], 0))
        quad(p(ro(z0),t0,z0), p(ro(z0),t1,z0), p(ro(z1),t1,z1), p(ro(z1),t0,z1), lambda c: (c[0], c[1], 0))
    quad(p(ri(0),t0,0), p(ri(0),t1,0), p(ro(0),t1,0), p(ro(0),t0,0), lambda c: (0, 0, -1))
    quad(p(ri(h),t0,h), p(ri(h),t1,h), p(ro(h),t1,h), p(ro(h),t0,h), lambda c: (0, 0, 1))
with open(sys.argv[1], "w") as f:
    f.write("solid hopper\n")
    for nrm, tri in tris:
        f.write("facet normal %.9g %.9g %.9g\nouter loop\n" % nrm)
        for v in tri: f.write("vertex %.9g %.9g %.9g\n" % v)
        f.write("endloop\nendfacet\n")
    f.write("endsolid hopper\n")
print(len(tris), "triangles")
