#!/usr/bin/env python3
"""The truth for the shape's factor (materials/geometry_factor.h), independent of lucent's code.

White Monte Carlo in numpy: a pencil beam enters a sphere of radius a (lengths in transport mean
free paths 1/sigma_t', isotropic scattering with the reduced coefficients) and, separately, a
half-space, refracted at incidence theta_t (the beam's angle inside); a smooth boundary of relative
index eta (exact Fresnel, total internal reflection). Each escaping photon is tallied by its chord
c = |x_o - x_i| from the entry (on a sphere the ring between c and c + dc has area 2 pi c dc, as on
a plane) with weight alpha'^n per reduced albedo (n scatterings). Prints, per configuration, the
ratio R_sphere(c) / R_plane(c) per bin: what the factor G must be (the planar profile times G is
the sphere's). Run: python3 sphere_factor_mc.py > sphere_factor_mc.md (about 4 minutes on 2 cores).
"""
import numpy as np

ALBEDOS = [0.999, 0.99, 0.95, 0.8]
# (radius a in mean free paths, eta, refracted angle theta_t in degrees, photons)
CONFIGS = [(1.5, 1.0, 0, 300000), (3.4, 1.3, 0, 300000), (5.0, 1.0, 0, 200000),
           (10.0, 1.5, 0, 200000), (5.0, 1.0, 70, 200000)]


def fresnel_inside(cos_i, eta):
    """Reflectance of unpolarised light meeting the boundary from inside (index eta; outside 1)."""
    sin_t2 = eta * eta * (1 - cos_i * cos_i)
    cos_t = np.sqrt(np.clip(1 - sin_t2, 0, 1))
    rs = (eta * cos_i - cos_t) / (eta * cos_i + cos_t)
    rp = (eta * cos_t - cos_i) / (eta * cos_t + cos_i)
    r = 0.5 * (rs * rs + rp * rp)
    r[sin_t2 >= 1] = 1
    return r


def run(a, eta, n, edges, theta_t, seed, max_steps=20000):
    """Exitance per unit area per bin of chord, per albedo, for n photons (a = inf: half-space)."""
    rng = np.random.default_rng(seed)
    half = not np.isfinite(a)
    entry = np.array([0, 0, 0.0 if half else a])
    p = np.tile(entry, (n, 1))
    d = np.zeros((n, 3))
    d[:, 0], d[:, 2] = np.sin(theta_t), -np.cos(theta_t)
    scatterings = np.zeros(n)
    alive = np.ones(n, bool)
    tally = np.zeros((len(ALBEDOS), len(edges) - 1))
    albedo = np.array(ALBEDOS)[:, None]
    for _ in range(max_steps):
        idx = np.nonzero(alive)[0]
        if len(idx) == 0:
            break
        step = -np.log(rng.random(len(idx)))
        pp, dd = p[idx], d[idx]
        q = pp + step[:, None] * dd
        if half:
            out = q[:, 2] > 0
            t = np.where(out, -pp[:, 2] / np.where(dd[:, 2] != 0, dd[:, 2], 1), step)
        else:
            out = (q * q).sum(1) > a * a
            b = (pp * dd).sum(1)
            c0 = (pp * pp).sum(1) - a * a
            t = np.where(out, -b + np.sqrt(np.maximum(b * b - c0, 0)), step)
        hit = pp + t[:, None] * dd
        # Collisions inside: isotropic scattering.
        k = idx[~out]
        p[k] = q[~out]
        scatterings[k] += 1
        cos_s = 1 - 2 * rng.random(len(k))
        sin_s = np.sqrt(1 - cos_s * cos_s)
        phi = 2 * np.pi * rng.random(len(k))
        d[k] = np.stack([sin_s * np.cos(phi), sin_s * np.sin(phi), cos_s], 1)
        # At the boundary: escape or reflect (Fresnel).
        k = idx[out]
        h = hit[out]
        normal = np.tile([0, 0, 1.0], (len(k), 1)) if half else h / a
        cos_i = np.clip((d[k] * normal).sum(1), 0, 1)
        escapes = rng.random(len(k)) >= fresnel_inside(cos_i, eta)
        chord = np.linalg.norm(h[escapes] - entry, axis=1)
        weights = albedo ** scatterings[k[escapes]][None, :]
        for j in range(len(ALBEDOS)):
            tally[j] += np.histogram(chord, edges, weights=weights[j])[0]
        alive[k[escapes]] = False
        kr = k[~escapes]
        p[kr] = h[~escapes] - 1e-9 * normal[~escapes]
        d[kr] -= 2 * cos_i[~escapes, None] * normal[~escapes]
    return tally / (np.pi * (edges[1:] ** 2 - edges[:-1] ** 2)) / n


def main():
    print("# The shape's factor's truth: R_sphere(c) / R_plane(c) by Monte Carlo\n")
    print("Written by `sphere_factor_mc.py` (numpy; independent of lucent's code). Lengths in")
    print("transport mean free paths; c the bin's chord from the entry (geometric centre; the last")
    print("four bins split the chord's last fifth up to the antipode 2a evenly).\n")
    for a, eta, theta, photons in CONFIGS:
        edges = np.concatenate([[0], np.geomspace(0.25, 1.6 * a, 11), np.linspace(1.6 * a, 2 * a, 5)[1:]])
        centre = np.sqrt(edges[1:] * edges[:-1])
        centre[0] = edges[1] / 2
        centre[-4:] = 0.5 * (edges[-5:-1] + edges[-4:])
        sphere = run(a, eta, photons, edges, np.radians(theta), 1)
        plane = run(np.inf, eta, photons, edges, np.radians(theta), 2)
        print(f"## a = {a} mfp, eta = {eta}, beam at {theta} degrees inside, {photons} photons each\n")
        print("| alpha' | " + " | ".join(f"{c:.2f}" for c in centre) + " |")
        print("|---" * (len(centre) + 1) + "|")
        for j, albedo in enumerate(ALBEDOS):
            print(f"| {albedo} | " + " | ".join(f"{x:.3f}" for x in sphere[j] / plane[j]) + " |")
        print()


if __name__ == "__main__":
    main()
