#!/usr/bin/python3
"""Per-region error of a picture of cornell-spheres (512 x 512, render's Cornell camera) against a
path-traced reference: each pixel classed by what its centre ray sees (lit, penumbra, umbra from the
lamp's 8 x 8 points; corners and contacts; the ceiling; the caustic disc; seen in the mirror or
through the glass; silhouettes). The classes take minutes in Python and are cached in CLASSES.npz.
DEN=3 divides each pixel's error by the 3 x 3 mean of the reference (as compare --picture does);
unset, by the pixel's own reference value.
usage: [DEN=3] regions.py TWO.pfm REF.pfm REF_se.pfm [CLASSES.npz]"""
import sys, os, math
import numpy as np

def read_pfm(p):
    with open(p, 'rb') as f:
        assert f.readline().strip() == b'PF'
        w, h = map(int, f.readline().split())
        scale = float(f.readline())
        a = np.frombuffer(f.read(), dtype='<f4' if scale < 0 else '>f4').reshape(h, w, 3)
    return a[::-1].astype(np.float64)

def lum(a): return 0.2126 * a[..., 0] + 0.7152 * a[..., 1] + 0.0722 * a[..., 2]

W = H = None
CAM = np.array([278., 273., -800.]); FOV = 39.0
SPH = [(np.array([370., 100., 370.]), 100., 'mirror'), (np.array([185., 100., 170.]), 100., 'glass')]
LAMP = (213., 343., 227., 332., 548.7)
CAUSTIC = np.array([164.273, 0., 145.596])
# box planes: (axis, value, inward normal sign)
PLANES = [(1, 0.0, 1, 'floor'), (1, 548.8, -1, 'ceiling'), (2, 559.2, -1, 'back'), (0, 0.0, 1, 'green'), (0, 554.4, -1, 'red')]

def rays(col, row, a=0.5, b=0.5):
    w = np.array([0, 0, 1.]); u = np.array([1., 0, 0]) * -1  # cross(w, up) = (0,0,1)x(0,1,0) = (-1,0,0)
    u = np.cross(w, [0, 1., 0]); v = np.cross(u, w)
    hh = math.tan(math.radians(FOV / 2)); hw = hh * W / H
    px = (col + a) / W; py = (row + b) / H
    d = w + (2 * px - 1) * hw * u + (1 - 2 * py) * hh * v
    return d / np.linalg.norm(d)

def hit_sphere(o, d, c, r):
    oc = o - c; b = oc @ d; cc = oc @ oc - r * r; disc = b * b - cc
    if disc < 0: return None
    s = math.sqrt(disc)
    for t in (-b - s, -b + s):
        if t > 1e-6: return t
    return None

def trace(o, d):
    best = (math.inf, None, None)
    for i, (c, r, name) in enumerate(SPH):
        t = hit_sphere(o, d, c, r)
        if t is not None and t < best[0]: best = (t, 'sphere', i)
    for k, (ax, val, sgn, name) in enumerate(PLANES):
        if abs(d[ax]) < 1e-12: continue
        t = (val - o[ax]) / d[ax]
        if t > 1e-6 and t < best[0] and d[ax] * sgn < 0: best = (t, 'plane', k)
    return best

def fresnel(cosi, n1, n2):
    s = n1 / n2 * math.sqrt(max(0, 1 - cosi * cosi))
    if s >= 1: return 1.0
    cost = math.sqrt(1 - s * s)
    rs = (n1 * cosi - n2 * cost) / (n1 * cosi + n2 * cost); rp = (n1 * cost - n2 * cosi) / (n1 * cost + n2 * cosi)
    return 0.5 * (rs * rs + rp * rp)

def ends_diffuse(o, d, depth=0, w=1.0):
    """True when every branch of weight >= 1e-3 ends on a non-emitting diffuse face."""
    t, kind, i = trace(o, d)
    if kind is None: return False
    p = o + t * d
    if kind == 'plane':
        if PLANES[i][3] == 'ceiling' and LAMP[0] <= p[0] <= LAMP[1] and LAMP[2] <= p[2] <= LAMP[3]: return False
        if p[2] < 0: return False
        return True
    if depth > 8: return True
    c, r, name = SPH[i]; n = (p - c) / r
    if name == 'mirror':
        return ends_diffuse(p + 1e-6 * n, d - 2 * (d @ n) * n, depth + 1, w)
    cosi = -(d @ n); entering = cosi > 0; f = n if entering else -n
    n1, n2 = (1.0, 1.5) if entering else (1.5, 1.0)
    ci = abs(cosi); F = fresnel(ci, n1, n2)
    ok = True
    if w * F >= 1e-2: ok = ends_diffuse(p + 1e-6 * f, d + 2 * ci * f, depth + 1, w * F)
    if F < 1 and ok:
        eta = n1 / n2; k = 1 - eta * eta * (1 - ci * ci)
        dt = eta * d + (eta * ci - math.sqrt(k)) * f
        if w * (1 - F) >= 1e-2: ok = ends_diffuse(p - 1e-6 * f, dt / np.linalg.norm(dt), depth + 1, w * (1 - F))
    return ok

def lamp_share(p, n=8):
    vis = 0
    for a in range(n):
        for b in range(n):
            q = np.array([LAMP[0] + (a + .5) / n * (LAMP[1] - LAMP[0]), LAMP[4], LAMP[2] + (b + .5) / n * (LAMP[3] - LAMP[2])])
            d = q - p; L = np.linalg.norm(d); d /= L
            blocked = any((t := hit_sphere(p, d, c, r)) is not None and t < L for c, r, _ in SPH)
            vis += not blocked
    return vis / n / n

def classify():
    cls = np.empty((H, W), dtype=object)
    mask = np.zeros((H, W), bool)
    for row in range(H):
        for col in range(W):
            d = rays(col, row)
            t, kind, i = trace(CAM, d)
            mask[row, col] = ends_diffuse(CAM, d)
            corner_kinds = set()
            for a, b in ((0, 0), (1, 0), (0, 1), (1, 1)):
                tk = trace(CAM, rays(col, row, a, b)); corner_kinds.add((tk[1], tk[2]))
            if kind == 'sphere':
                cls[row, col] = 'silhouette' if len(corner_kinds) > 1 else ('through mirror' if i == 0 else 'through glass')
                continue
            if len(corner_kinds) > 1 and any(k[0] == 'sphere' for k in corner_kinds):
                cls[row, col] = 'silhouette'; continue
            p = CAM + t * d; name = PLANES[i][3]
            if name == 'floor' and np.hypot(p[0] - CAUSTIC[0], p[2] - CAUSTIC[2]) < 50: cls[row, col] = 'caustic'; continue
            near_edge = min(abs(p[ax] - val) for ax, val, _, nm in PLANES if nm != name and not (nm in ('green','red') and name in ('green','red'))) < 30
            near_contact = name == 'floor' and min(np.hypot(p[0] - c[0], p[2] - c[2]) for c, _, _ in SPH) < 70
            if near_edge or near_contact: cls[row, col] = 'corner/contact'; continue
            if name == 'ceiling': cls[row, col] = 'ceiling (indirect)'; continue
            s = lamp_share(p + 1e-6 * np.eye(3)[PLANES[i][0]] * PLANES[i][2])
            cls[row, col] = 'lit' if s >= 1 else ('umbra' if s <= 0 else 'penumbra')
    return cls, mask

def main():
    global W, H
    two = read_pfm(sys.argv[1]); ref = read_pfm(sys.argv[2]); se = read_pfm(sys.argv[3])
    H, W = ref.shape[:2]
    cache = sys.argv[4] if len(sys.argv) > 4 else f'classes_{W}x{H}.npz'
    if os.path.exists(cache):
        z = np.load(cache, allow_pickle=True); cls, mask = z['cls'], z['mask']
    else:
        cls, mask = classify(); np.savez(cache, cls=cls, mask=mask)
    yt, yr, ys = lum(two), lum(ref), lum(se)
    ok = mask & (yr > 0)
    if os.environ.get('DEN'):
        from scipy.ndimage import uniform_filter
        k = int(os.environ['DEN'])
        den = uniform_filter(np.where(ok, yr, 0), k, mode='constant') / np.maximum(uniform_filter(ok.astype(float), k, mode='constant'), 1e-9)
        yrd = np.where(ok, den, 1)
    else:
        yrd = np.where(yr > 0, yr, 1)
    e = np.where(ok, (yt - yr) / yrd, 0); nz = np.where(ok, ys / yrd, 0)
    tot = (e[ok] ** 2).sum(); nt = (nz[ok] ** 2).sum(); N = ok.sum()
    print(f'{N} pixels scored: RMS {100*math.sqrt(tot/N):.2f}%, ref noise {100*math.sqrt(nt/N):.2f}%, less noise {100*math.sqrt(max(0,tot-nt)/N):.2f}%')
    print(f'{"class":20s} {"pixels":>7s} {"RMS":>7s} {"noise":>7s} {"less":>7s} {"mean":>7s} {"share of err^2 less noise":>10s}')
    for c in sorted(set(cls[ok])):
        sel = ok & (cls == c); n = sel.sum()
        s2 = (e[sel] ** 2).sum(); n2 = (nz[sel] ** 2).sum()
        print(f'{c:20s} {n:7d} {100*math.sqrt(s2/n):6.2f}% {100*math.sqrt(n2/n):6.2f}% {100*math.sqrt(max(0,s2-n2)/n):6.2f}% {100*e[sel].mean():+6.2f}% {100*(s2-n2)/(tot-nt):9.1f}%')
    # 2x2 binned: reference noise halves
    def b2(a): return a[:H//2*2, :W//2*2].reshape(H//2, 2, W//2, 2).mean(axis=(1, 3))
    okb = b2(ok.astype(float)) == 1
    ytb, yrb = b2(np.where(ok, yt, 0)), b2(np.where(ok, yr, 0)); ysb = np.sqrt(b2(np.where(ok, ys**2, 0))) / 2
    eb = ((ytb - yrb) / np.where(yrb > 0, yrb, 1))[okb]; nb = (ysb / np.where(yrb > 0, yrb, 1))[okb]
    print(f'2x2 binned: RMS {100*math.sqrt((eb**2).mean()):.2f}%, noise {100*math.sqrt((nb**2).mean()):.2f}%, less noise {100*math.sqrt(max(0,(eb**2).mean()-(nb**2).mean())):.2f}%')

if __name__ == '__main__':
    main()
