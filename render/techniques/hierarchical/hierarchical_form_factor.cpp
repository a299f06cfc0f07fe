// The semi-analytic subsurface form factor (hierarchical_form_factor.h has the derivation and its
// corrections of the seed).
#include "lucent/render/hierarchical_form_factor.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <numbers>

#include "lucent/core/error.h"

namespace lucent::render::hierarchical {

SegmentRule parse_segment_rule(const std::string& text) {
  if (text == "midpoint") return SegmentRule::kSeedMidpoint;
  if (text == "gauss2") return SegmentRule::kGauss2;
  throw Error("--hierarchical-rule: expected midpoint (the seed's eq. 17) or gauss2, got '" + text +
              "'");
}

DipolePlacement parse_dipole_placement(const std::string& text) {
  if (text == "chord") return DipolePlacement::kChord;
  if (text == "seed") return DipolePlacement::kSeed3d;
  throw Error(
      "--hierarchical-dipole: expected chord (lucent's R_d) or seed (sources at x -/+ z N), got '" +
      text + "'");
}

std::string to_string(SegmentRule rule) {
  return rule == SegmentRule::kSeedMidpoint ? "midpoint" : "gauss2";
}

std::string to_string(DipolePlacement placement) {
  return placement == DipolePlacement::kChord ? "chord" : "seed";
}

PlaneFrame PlaneFrame::from_normal(const Vec3d& origin, const Vec3d& normal) {
  PlaneFrame f;
  f.origin = origin;
  f.n = normal.normalized();
  // The tangent from the axis least aligned with n.
  const Vec3d a = std::abs(f.n.x()) < 0.6 ? Vec3d::UnitX()
                  : std::abs(f.n.y()) < 0.6 ? Vec3d::UnitY()
                                            : Vec3d::UnitZ();
  f.u = (a - a.dot(f.n) * f.n).normalized();
  f.v = f.n.cross(f.u);
  return f;
}

void dipole_sources(const materials::DiffusionCoefficients<double>& c, const Vec3d& x_o,
                    const Vec3d& n_o, const PlaneFrame& plane, DipolePlacement placement,
                    PlaneSource out[2]) {
  const double z[2] = {c.z_r, c.z_v};
  if (placement == DipolePlacement::kChord) {
    const double h_o = (x_o - plane.origin).dot(plane.n);
    const Vec2d pole = plane.project(x_o);
    for (int k = 0; k < 2; ++k) out[k] = {z[k], std::sqrt(h_o * h_o + z[k] * z[k]), pole};
    return;
  }
  // The seed's placement: the real source below x_o, the virtual one above, along n_o. A source on
  // the polygon's plane would make e^(-sigma H) / H unbounded: H is floored at 1e-3 z_r.
  const Vec3d points[2] = {x_o - c.z_r * n_o, x_o + c.z_v * n_o};
  for (int k = 0; k < 2; ++k) {
    const double H = std::abs((points[k] - plane.origin).dot(plane.n));
    out[k] = {z[k], std::max(H, 1e-3 * c.z_r), plane.project(points[k])};
  }
}

namespace {

double cross2(const Vec2d& a, const Vec2d& b) { return a.x() * b.y() - a.y() * b.x(); }

// The integrand of I2 / (z R) in t, measured along the edge from the pole's foot on its line.
struct EdgeIntegrand {
  double R2, H2, sigma;
  double operator()(double t) const {
    const double r2 = R2 + t * t;
    const double s = std::sqrt(r2 + H2);
    return std::exp(-sigma * s) / (s * r2);
  }
};

double integrate_segments(const EdgeIntegrand& g, double R, double t_lo, double t_hi, int depth,
                          const FormFactorOptions& o, long& segments) {
  const double L = t_hi - t_lo, t0 = 0.5 * (t_lo + t_hi);
  const double r0 = std::sqrt(R * R + t0 * t0);
  const bool fine = L < o.edge_constant * r0 && (!o.global_condition || L * g.sigma < o.edge_constant);
  if (!fine && depth < o.max_depth) {
    return integrate_segments(g, R, t_lo, t0, depth + 1, o, segments) +
           integrate_segments(g, R, t0, t_hi, depth + 1, o, segments);
  }
  ++segments;
  if (o.rule == SegmentRule::kSeedMidpoint) return g(t0) * L;
  const double h = 0.5 * L / std::sqrt(3.0);  // Gauss-Legendre nodes t0 -/+ L / (2 sqrt 3)
  return 0.5 * L * (g(t0 - h) + g(t0 + h));
}

// The sources of the chord placement (both, and every colour channel's) share the pole, so the
// edge's geometry and angle; the subdivision depends on the edge, the pole and sigma only. N
// channels' integrands are summed in one traversal: a channel stops splitting where it alone would
// (L sigma < c is its own), and each channel's segments, values and sums are those of its own
// traversal, bit for bit.
template <std::size_t N>
struct SharedPoleIntegrand {
  double R2 = 0;
  std::array<double, N> sigma{};
  std::array<std::array<double, 2>, N> H2{};  // real, virtual source
  // EdgeIntegrand's value, r2 = R^2 + t^2 computed once for all.
  double operator()(std::size_t ch, std::size_t k, double r2) const {
    const double s = std::sqrt(r2 + H2[ch][k]);
    return std::exp(-sigma[ch] * s) / (s * r2);
  }
};

template <std::size_t N>
using SourceSums = std::array<std::array<double, 2>, N>;  // per channel: real, virtual

// `active`: a bit per channel still integrating; out[ch] written for those only.
template <std::size_t N>
void integrate_shared_pole(const SharedPoleIntegrand<N>& g, double R, double t_lo, double t_hi,
                           int depth, unsigned active, const FormFactorOptions& o, long& segments,
                           SourceSums<N>& out) {
  const double L = t_hi - t_lo, t0 = 0.5 * (t_lo + t_hi);
  const double r0 = std::sqrt(R * R + t0 * t0);
  const bool near_fine = L < o.edge_constant * r0;
  unsigned split = 0;
  for (std::size_t ch = 0; ch < N; ++ch) {
    if (!(active >> ch & 1u)) continue;
    const bool fine = near_fine && (!o.global_condition || L * g.sigma[ch] < o.edge_constant);
    if (!fine && depth < o.max_depth) {
      split |= 1u << ch;
      continue;
    }
    segments += 2;  // one per source, as edge_term counts them
    if (o.rule == SegmentRule::kSeedMidpoint) {
      const double r2 = g.R2 + t0 * t0;
      for (std::size_t k = 0; k < 2; ++k) out[ch][k] = g(ch, k, r2) * L;
    } else {
      const double h = 0.5 * L / std::sqrt(3.0);  // Gauss-Legendre nodes t0 -/+ L / (2 sqrt 3)
      const double r2a = g.R2 + (t0 - h) * (t0 - h), r2b = g.R2 + (t0 + h) * (t0 + h);
      for (std::size_t k = 0; k < 2; ++k) out[ch][k] = 0.5 * L * (g(ch, k, r2a) + g(ch, k, r2b));
    }
  }
  if (!split) return;
  SourceSums<N> a, b;
  integrate_shared_pole(g, R, t_lo, t0, depth + 1, split, o, segments, a);
  integrate_shared_pole(g, R, t0, t_hi, depth + 1, split, o, segments, b);
  for (std::size_t ch = 0; ch < N; ++ch) {
    if (!(split >> ch & 1u)) continue;
    for (std::size_t k = 0; k < 2; ++k) out[ch][k] = a[ch][k] + b[ch][k];
  }
}

// F of N channels whose sources all share one pole (kChord), `active` the channels that scatter:
// per channel alpha' / (4 pi) x the sum over edges of Gamma_e of the real plus the virtual
// source.
template <std::size_t N>
std::array<double, N> shared_pole_form_factor(
    const std::array<const materials::DiffusionCoefficients<double>*, N>& c,
    const std::array<std::array<PlaneSource, 2>, N>& sources, unsigned active,
    std::span<const Vec2d> edge_starts, std::span<const Vec2d> edge_ends,
    const FormFactorOptions& options, FormFactorCounters* counters) {
  // I1's per-source factor z e^(-sigma H) / H does not depend on the edge.
  std::array<std::array<double, 2>, N> I1_factor{};
  SharedPoleIntegrand<N> g;
  for (std::size_t ch = 0; ch < N; ++ch) {
    if (!(active >> ch & 1u)) continue;
    g.sigma[ch] = c[ch]->sigma_tr;
    for (std::size_t k = 0; k < 2; ++k) {
      const PlaneSource& s = sources[ch][k];
      I1_factor[ch][k] = s.z * std::exp(-c[ch]->sigma_tr * s.H) / s.H;
      g.H2[ch][k] = s.H * s.H;
    }
  }
  const Vec2d pole = sources[0][0].pole;
  std::array<double, N> sum{};
  long segments = 0;
  for (std::size_t e = 0; e < edge_starts.size(); ++e) {
    const Vec2d& a = edge_starts[e];
    const Vec2d& b = edge_ends[e];
    const Vec2d pa = a - pole, pb = b - pole;
    const double L = (b - a).norm();
    if (!(L > 0)) continue;
    const Vec2d u = (b - a) / L;
    const double R = cross2(pa, u);
    const double t1 = pa.dot(u), t2 = t1 + L;
    if (std::abs(R) <= 1e-12 * (std::abs(t1) + std::abs(t2) + L)) continue;  // as edge_term
    const double dtheta = std::atan2(cross2(pa, pb), pa.dot(pb));
    g.R2 = R * R;
    SourceSums<N> I2;
    integrate_shared_pole(g, R, t1, t2, 0, active, options, segments, I2);
    for (std::size_t ch = 0; ch < N; ++ch) {
      if (!(active >> ch & 1u)) continue;
      const double I1 = (I1_factor[ch][0] + I1_factor[ch][1]) * dtheta;
      sum[ch] += I1 - R * (sources[ch][0].z * I2[ch][0] + sources[ch][1].z * I2[ch][1]);
    }
  }
  if (counters) counters->segments += segments;
  std::array<double, N> F{};
  for (std::size_t ch = 0; ch < N; ++ch) {
    if (active >> ch & 1u) F[ch] = c[ch]->alpha_prime / (4 * std::numbers::pi) * sum[ch];
  }
  return F;
}

}  // namespace

double edge_term(const PlaneSource& source, double sigma_tr, const Vec2d& a, const Vec2d& b,
                 const FormFactorOptions& options, FormFactorCounters* counters) {
  const Vec2d pa = a - source.pole, pb = b - source.pole;
  const double L = (b - a).norm();
  if (!(L > 0)) return 0;
  const Vec2d u = (b - a) / L;
  const double R = cross2(pa, u);  // signed: dtheta / dt = R / (R^2 + t^2)
  const double t1 = pa.dot(u), t2 = t1 + L;
  // A pole on the edge's line (at a vertex, or on the edge itself): the wedge from the pole to the
  // edge has no area, and I1 - I2 -> 0 as R -> 0 (I2's R / (R^2 + t^2) tends to pi delta(t), the
  // angle to pi). Return the limit rather than resolve the spike.
  if (std::abs(R) <= 1e-12 * (std::abs(t1) + std::abs(t2) + L)) return 0;
  const double dtheta = std::atan2(cross2(pa, pb), pa.dot(pb));
  const double I1 = source.z * std::exp(-sigma_tr * source.H) / source.H * dtheta;
  long segments = 0;
  const EdgeIntegrand g{R * R, source.H * source.H, sigma_tr};
  const double I2 = source.z * R * integrate_segments(g, R, t1, t2, 0, options, segments);
  if (counters) counters->segments += segments;
  return I1 - I2;
}

double edges_form_factor(const materials::DiffusionCoefficients<double>& c, const Vec3d& x_o,
                         const Vec3d& n_o, const PlaneFrame& plane,
                         std::span<const Vec2d> edge_starts, std::span<const Vec2d> edge_ends,
                         const FormFactorOptions& options, FormFactorCounters* counters) {
  if (counters) ++counters->calls;
  if (!c.scatters()) return 0;
  std::array<std::array<PlaneSource, 2>, 1> sources;
  dipole_sources(c, x_o, n_o, plane, options.placement, sources[0].data());
  if (sources[0][0].pole == sources[0][1].pole) {
    return shared_pole_form_factor<1>({&c}, sources, 1u, edge_starts, edge_ends, options,
                                      counters)[0];
  }
  double sum = 0;
  for (const PlaneSource& s : sources[0]) {
    for (std::size_t e = 0; e < edge_starts.size(); ++e) {
      sum += edge_term(s, c.sigma_tr, edge_starts[e], edge_ends[e], options, counters);
    }
  }
  return c.alpha_prime / (4 * std::numbers::pi) * sum;
}

std::array<double, 3> edges_form_factor_rgb(
    const std::array<materials::DiffusionCoefficients<double>, 3>& c, const Vec3d& x_o,
    const Vec3d& n_o, const PlaneFrame& plane, std::span<const Vec2d> edge_starts,
    std::span<const Vec2d> edge_ends, const FormFactorOptions& options,
    FormFactorCounters* counters) {
  std::array<double, 3> F{};
  if (options.placement != DipolePlacement::kChord) {  // the poles differ between channels
    for (std::size_t ch = 0; ch < 3; ++ch) {
      F[ch] = edges_form_factor(c[ch], x_o, n_o, plane, edge_starts, edge_ends, options, counters);
    }
    return F;
  }
  if (counters) counters->calls += 3;
  std::array<std::array<PlaneSource, 2>, 3> sources;
  unsigned active = 0;
  for (std::size_t ch = 0; ch < 3; ++ch) {
    if (!c[ch].scatters()) continue;
    active |= 1u << ch;
    dipole_sources(c[ch], x_o, n_o, plane, options.placement, sources[ch].data());
  }
  if (!active) return F;
  // A channel that does not scatter has no sources; the pole is any other's.
  for (std::size_t ch = 0; ch < 3; ++ch) {
    if (!(active >> ch & 1u)) sources[ch] = sources[std::size_t(std::countr_zero(active))];
  }
  return shared_pole_form_factor<3>({&c[0], &c[1], &c[2]}, sources, active, edge_starts, edge_ends,
                                    options, counters);
}

double triangle_form_factor(const materials::DiffusionCoefficients<double>& c, const Vec3d& x_o,
                            const Vec3d& n_o, const Vec3d& a, const Vec3d& b, const Vec3d& v_c,
                            const FormFactorOptions& options, FormFactorCounters* counters) {
  const Vec3d normal = (b - a).cross(v_c - a);
  if (!(normal.norm() > 0)) {
    if (counters) ++counters->calls;
    return 0;  // a degenerate triangle has no area
  }
  const PlaneFrame plane = PlaneFrame::from_normal(a, normal);
  const Vec2d p[3] = {plane.project(a), plane.project(b), plane.project(v_c)};
  const Vec2d starts[3] = {p[0], p[1], p[2]}, ends[3] = {p[1], p[2], p[0]};
  return edges_form_factor(c, x_o, n_o, plane, starts, ends, options, counters);
}

double point_form_factor(const materials::DiffusionCoefficients<double>& c, const Vec3d& x_o,
                         const Vec3d& n_o, const Vec3d& midpoint, double area,
                         DipolePlacement placement) {
  if (!c.scatters()) return 0;
  auto term = [&](double z, double s) {
    return z * (1 + c.sigma_tr * s) * std::exp(-c.sigma_tr * s) / (s * s * s);
  };
  double sr, sv;
  if (placement == DipolePlacement::kChord) {
    const double r2 = (midpoint - x_o).squaredNorm();
    sr = std::sqrt(r2 + c.z_r * c.z_r);
    sv = std::sqrt(r2 + c.z_v * c.z_v);
  } else {
    sr = std::max((midpoint - (x_o - c.z_r * n_o)).norm(), 1e-3 * c.z_r);
    sv = std::max((midpoint - (x_o + c.z_v * n_o)).norm(), 1e-3 * c.z_r);
  }
  return area * c.alpha_prime / (4 * std::numbers::pi) * (term(c.z_r, sr) + term(c.z_v, sv));
}

}  // namespace lucent::render::hierarchical
