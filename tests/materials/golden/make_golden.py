#!/usr/bin/env python3
"""Golden values for the dipole tests from an independent transcription in plain Python.

The directional dipole here follows the structure of Frisvad, Hachisuka and Kjeldsen's own sample
code (profile function Sp_d, modified normal, real/virtual source distances), written separately
from the C++ in materials/ so that a transcription error in either shows up as a mismatch. One
departure from the sample code: below eta = 1 the second Fresnel moment is its definition
integrated here (the code's fit is wrong there), as lucent computes it.
Run: python3 make_golden.py > golden_bssrdf.csv
"""
import math
import random

def dot(a, b): return a[0]*b[0] + a[1]*b[1] + a[2]*b[2]
def sub(a, b): return [a[i]-b[i] for i in range(3)]
def add(a, b): return [a[i]+b[i] for i in range(3)]
def mul(a, s): return [a[i]*s for i in range(3)]
def cross(a, b): return [a[1]*b[2]-a[2]*b[1], a[2]*b[0]-a[0]*b[2], a[0]*b[1]-a[1]*b[0]]
def length(a): return math.sqrt(dot(a, a))
def normalize(a): return mul(a, 1.0/length(a))

def C1(n):
    if n > 1.0:
        return (-9.23372 + 22.2272*n - 20.9292*n**2 + 10.2291*n**3 - 2.54396*n**4 + 0.254913*n**5) / 2
    return (0.919317 - 3.4793*n + 6.75335*n**2 - 7.80989*n**3 + 4.98554*n**4 - 1.36881*n**5) / 2

def fresnel_R(cos_i, eta):
    """Unpolarised Fresnel reflectance, light arriving at cos_i, relative index eta = n_t / n_i."""
    sin2_t = (1 - cos_i*cos_i) / (eta*eta)
    if sin2_t >= 1: return 1.0
    cos_t = math.sqrt(1 - sin2_t)
    rs = (cos_i - eta*cos_t) / (cos_i + eta*cos_t)
    rp = (eta*cos_i - cos_t) / (eta*cos_i + cos_t)
    return 0.5*(rs*rs + rp*rp)

def C2(n):
    if n < 1.0:
        # The sample code's single fit is not the moment below 1 (C_E(0.8) = 0.12 for 0.486): the
        # definition, integral of F_r(mu, 1/n) mu^2 dmu over [0, 1], by composite Simpson (4000
        # intervals; no total internal reflection from the optically thinner side).
        m = 4000
        h = 1.0 / m
        total = 0.0
        for k in range(m + 1):
            mu = k * h
            w = 1 if k in (0, m) else (4 if k % 2 else 2)
            total += w * fresnel_R(mu, 1.0/n) * mu*mu
        return total * h / 3
    return (-1641.1 + 1213.67*n - 568.556*n**2 + 164.798*n**3 - 27.0181*n**4 + 1.91826*n**5
            + 1376.53/n - 656.175/n**2 + 135.926/n**3) / 3

def C_phi(n): return 0.25*(1 - 2*C1(n))
def C_E(n): return 0.5*(1 - 3*C2(n))

def F_dr(eta): return -1.440/eta**2 + 0.710/eta + 0.668 + 0.0636*eta

def dipole_Rd(sa, ssp, eta, r):
    stp = sa + ssp
    ap = ssp/stp
    D = 1/(3*stp)
    st = math.sqrt(3*sa*stp)
    zr = 1/stp
    A = (1 + F_dr(eta))/(1 - F_dr(eta))
    zv = zr + 4*A*D
    dr = math.sqrt(r*r + zr*zr)
    dv = math.sqrt(r*r + zv*zv)
    return ap/(4*math.pi)*(zr*(1 + st*dr)*math.exp(-st*dr)/dr**3 + zv*(1 + st*dv)*math.exp(-st*dv)/dv**3)

class DirectionalDipole:
    def __init__(self, sigma_a, sigma_s, g, eta):
        self.eta = eta
        sigma_sp = sigma_s*(1 - g)
        self.sigma_t = sigma_a + sigma_s
        sigma_tp = sigma_a + sigma_sp
        alpha_p = sigma_sp/sigma_tp
        self.D = 1/(3*sigma_tp)
        self.sigma_tr = math.sqrt(sigma_a/self.D)
        self.de = 2.131*self.D/math.sqrt(alpha_p)
        self.cphi = C_phi(eta)
        self.ce = C_E(eta)
        self.A = (1 - self.ce)/(2*self.cphi)
        self.norm = 1/(4*C_phi(1/eta))

    def Sp_d(self, x, w, r, n):
        s_tr_r = self.sigma_tr*r
        s_tr_r_one = 1 + s_tr_r
        x_dot_w = dot(x, w)
        r_sqr = r*r
        t0 = self.norm/(4*math.pi**2)*math.exp(-s_tr_r)/(r*r_sqr)
        t1 = r_sqr/self.D + 3*s_tr_r_one*x_dot_w
        t2 = 3*self.D*s_tr_r_one*dot(w, n)
        t3 = (s_tr_r_one + 3*self.D*(3*s_tr_r_one + s_tr_r*s_tr_r)/r_sqr*x_dot_w)*dot(x, n)
        return t0*(self.cphi*t1 - self.ce*(t2 - t3))

    def S_d(self, xi, ni, wi, xo, no):
        xoxi = sub(xo, xi)
        r = length(xoxi)
        ni_s = cross(normalize(xoxi), normalize(cross(ni, xoxi)))
        nnt = 1/self.eta
        ddn = -dot(wi, ni)   # minus the cosine of incidence (w_i points toward the light)
        # refract the incoming direction -wi
        wr = normalize(sub(mul(wi, -nnt), mul(ni, ddn*nnt + math.sqrt(1 - nnt*nnt*(1 - ddn*ddn)))))
        wv = sub(wr, mul(ni_s, 2*dot(wr, ni_s)))
        cos_beta = -math.sqrt((r*r - dot(xoxi, wr)**2)/(r*r + self.de**2))
        mu0 = -dot(no, wr)
        if mu0 > 0:
            dr = math.sqrt((self.D*mu0)*((self.D*mu0) - self.de*cos_beta*2) + r*r)
        else:
            dr = math.sqrt(1/(3*self.sigma_t)**2 + r*r)
        xoxv = sub(xo, add(xi, mul(ni_s, 2*self.A*self.de)))
        dv = length(xoxv)
        result = self.Sp_d(xoxi, wr, dr, no) - self.Sp_d(xoxv, wv, dv, no)
        return max(result, 0.0)

def unit(rng):
    while True:
        v = [rng.uniform(-1, 1) for _ in range(3)]
        l = length(v)
        if 0.1 < l <= 1: return mul(v, 1/l)

def main():
    rng = random.Random(20261122)
    print("sigma_a,sigma_s,g,eta,xi_x,xi_y,xi_z,ni_x,ni_y,ni_z,wi_x,wi_y,wi_z,"
          "xo_x,xo_y,xo_z,no_x,no_y,no_z,Sd_ddipole,Rd_dipole")
    fmt = lambda v: repr(float(v))
    for i in range(200):
        sigma_a = 10**rng.uniform(-3, 0.5)
        sigma_s = 10**rng.uniform(-1, 1)
        g = rng.uniform(-0.3, 0.9)
        eta = rng.uniform(1.05, 1.8) if i % 5 else rng.uniform(0.7, 0.95)
        xi = [rng.uniform(-1, 1) for _ in range(3)]
        ni = unit(rng)
        wi = unit(rng)
        if dot(wi, ni) < 0.05: wi = sub(wi, mul(ni, 2*dot(wi, ni) - 0.1))
        wi = normalize(wi)
        # Skip directions beyond the critical angle for eta < 1 (the sample code takes sqrt of < 0).
        if 1 - (1 - dot(wi, ni)**2)/eta**2 < 0: continue
        xo = add(xi, mul(unit(rng), 10**rng.uniform(-2, 1)))
        no = unit(rng)
        dd = DirectionalDipole(sigma_a, sigma_s, g, eta)
        S = dd.S_d(xi, ni, wi, xo, no)
        Rd = dipole_Rd(sigma_a, sigma_s*(1 - g), eta, length(sub(xo, xi))) if eta >= 1 else float('nan')
        print(",".join(fmt(v) for v in [sigma_a, sigma_s, g, eta, *xi, *ni, *wi, *xo, *no, S, Rd]))

if __name__ == "__main__":
    main()
