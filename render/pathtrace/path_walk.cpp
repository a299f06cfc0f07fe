// One path (path_walk.h), the three channels together: from the camera through the boundary's
// Fresnel events into the medium, collision after collision (free paths drawn from the channels'
// mixture, Henyey-Greenstein turns), with next-event estimates of every light at every collision,
// until it leaves the scene or roulette ends it.
#include <algorithm>

#include "lucent/core/error.h"
#include "lucent/materials/fresnel.h"
#include "path_walk.h"

namespace lucent::render::pathtrace {
namespace {

constexpr double kRouletteBelow = 0.05;

// The length of the straight segment from x (inside) along w, up to max_distance, that lies inside
// the mesh: the optical depth over sigma_t (eta = 1: the boundary does not bend the ray).
double inside_length(const Boundary& boundary, const Vec3d& x, const Vec3d& w,
                     double max_distance) {
  double inside = 0, travelled = 0;
  bool in = true;
  Vec3d o = x;
  for (int crossing = 0; crossing < 256; ++crossing) {
    const auto hit = boundary.hit(o, w, max_distance - travelled);
    if (!hit) {
      if (in && std::isfinite(max_distance)) inside += max_distance - travelled;
      return inside;
    }
    if (in) inside += hit->t;
    if (in && boundary.convex()) return inside;  // out, and never back in
    travelled += hit->t;
    in = w.dot(hit->ng) < 0;  // crossed inward: inside from here
    o = boundary.offset(*hit, w);
  }
  return inside;
}

// A uniform point on an area emitter.
Vec3d sample_area(const AreaEmitter& e, Random& random) {
  const double target = random.uniform() * e.area;
  std::size_t i = 1;
  while (i + 1 < e.cdf.size() && e.cdf[i] < target) ++i;
  const double s = std::sqrt(random.uniform()), t = random.uniform();
  const Vec3d& a = e.polygon[0];
  const Vec3d& b = e.polygon[i];
  const Vec3d& c = e.polygon[i + 1];
  return a + s * (1 - t) * (b - a) + s * t * (c - a);
}

double balance(double mine, double other) {
  return mine / (mine + other);
}

// The channels' shares of a sample: their throughputs, normalised (equal where all are 0).
Rgb shares_of(const Rgb& beta) {
  const double sum = beta.sum();
  return sum > 0 ? Rgb(beta / sum) : Rgb::Constant(1.0 / 3);
}

// A channel picked in proportion to `share`.
int pick_channel(const Rgb& share, double xi) {
  if (xi < share[0]) return 0;
  return xi < share[0] + share[1] ? 1 : 2;
}

// The phase sample's density under the channels' mixture, and its direction.
double mixture_phase_pdf(const MediumRgb& m, const Rgb& share, double cos_theta) {
  if (m.one_phase) return m.phase[0].pdf(cos_theta);
  return (share * m.phase_pdf(cos_theta)).sum();
}

// A delta light straight through an invisible boundary: phase x irradiance x transmittance.
Rgb straight_delta(const World& w, const Light& light, const Vec3d& x, const Vec3d& toward) {
  Vec3d to_light;
  double distance = std::numeric_limits<double>::infinity(), falloff = 1;
  if (light.type == LightType::kDirectional) {
    to_light = light.direction.cast<double>().normalized();
  } else {
    to_light = light.position.cast<double>() - x;
    distance = to_light.norm();
    if (!(distance > 0)) return Rgb::Zero();
    to_light /= distance;
    falloff = 1 / (distance * distance);
  }
  const double length = inside_length(w.boundary, x, to_light, distance);
  return w.medium.phase_pdf(-to_light.dot(toward)) * falloff * (-w.medium.sigma_t * length).exp();
}

Rgb radiance_of(const Vec3f& v) {
  return v.cast<double>().array();
}

}  // namespace

Rgb next_event(const World& w, const Vec3d& x, const Vec3d& toward, Random& random,
               WalkCounts& counts, const Rgb* share) {
  const MediumRgb& m = w.medium;
  // MIS against the phase sample's escape where it also counts (eta = 1 and the path goes on).
  const auto weight = [&](double mine, const Vec3d& direction) {
    if (share == nullptr) return 1.0;
    return balance(mine, mixture_phase_pdf(m, *share, direction.dot(-toward)));
  };
  Rgb sum = Rgb::Zero();
  for (const Light& light : w.lights.delta) {
    const Rgb value = radiance_of(light.radiance);
    if (!(value.maxCoeff() > 0)) continue;
    if (w.matched) {
      sum += value * straight_delta(w, light, x, toward);
      continue;
    }
    Connection link;
    const Link outcome = refracted_connection(w, light, x, link);
    counts.count(outcome);
    if (outcome == Link::kConnected) {
      sum += value * m.phase_pdf(link.travel.dot(toward)) * link.irradiance *
             (-m.sigma_t * link.distance).exp();
    }
  }
  for (const AreaEmitter& e : w.lights.area) {
    const Rgb value = e.radiance.array();
    if (!(value.maxCoeff() > 0)) continue;
    const Vec3d y = sample_area(e, random);
    if (w.matched) {
      Vec3d to_light = y - x;
      const double distance = to_light.norm();
      to_light /= distance;
      const double cos_light = -to_light.dot(e.normal);
      if (!(cos_light > 0)) continue;
      const double length = inside_length(w.boundary, x, to_light, distance);
      const double p_light = distance * distance / (cos_light * e.area);  // per sr
      sum += value * m.phase_pdf(-to_light.dot(toward)) * (-m.sigma_t * length).exp() / p_light *
             weight(p_light, to_light);
      continue;
    }
    // Through the refracting boundary: the point y as a point light of intensity L cos A.
    Light point;
    point.type = LightType::kPoint;
    point.position = y.cast<float>();
    Connection link;
    const Link outcome = refracted_connection(w, point, x, link);
    counts.count(outcome);
    if (outcome == Link::kConnected) {
      const double cos_light = (link.exit - y).normalized().dot(e.normal);
      if (cos_light > 0) {
        sum += value * cos_light * e.area * m.phase_pdf(link.travel.dot(toward)) * link.irradiance *
               (-m.sigma_t * link.distance).exp();
      }
    }
  }
  if (w.matched && w.lights.environment_sampler && !w.lights.environment_sampler->black()) {
    double pdf = 0;
    const Vec3d dir = w.lights.environment_sampler->sample(random.uniform(), random.uniform(), pdf)
                          .cast<double>();
    if (pdf > 0) {
      const double length =
          inside_length(w.boundary, x, dir, std::numeric_limits<double>::infinity());
      const Rgb sky = w.lights.background(dir);
      sum += sky * m.phase_pdf(-dir.dot(toward)) * (-m.sigma_t * length).exp() / pdf *
             weight(pdf, dir);
    }
  }
  return sum;
}

namespace {

// A free path from a surface point (or a collision) drawn from the channels' mixture: true and the
// distance s when it ends in a collision before `boundary` mm, with the channels' weights
// sigma_s e^(-sigma_t s) / mixture density folded into beta; false when it reaches the boundary
// first, with e^(-sigma_t boundary) / the probability of getting there folded in.
// In two steps, for the caller that tests the segment before it looks for the boundary: the
// distance (draw_free_path), then its weight once it is known to end in a collision
// (collision_weight) or to reach the boundary first (boundary_weight).
double draw_free_path(const MediumRgb& m, const Rgb& share, Random& random) {
  const int k = pick_channel(share, random.uniform());
  const double sigma = m.sigma_t[k];
  return sigma > 0 ? -std::log(1 - random.uniform()) / sigma
                   : std::numeric_limits<double>::infinity();
}
void collision_weight(const MediumRgb& m, const Rgb& share, double s, Rgb& beta) {
  const Rgb survive = (-m.sigma_t * s).exp();
  const double pdf = (share * m.sigma_t * survive).sum();
  beta *= m.sigma_s * survive / pdf;
}
void boundary_weight(const MediumRgb& m, const Rgb& share, double boundary, Rgb& beta) {
  const Rgb survive = (-m.sigma_t * boundary).exp();
  beta *= survive / (share * survive).sum();
}

bool free_path(const MediumRgb& m, const Rgb& share, double boundary, Random& random, Rgb& beta,
               double& s) {
  s = draw_free_path(m, share, random);
  if (s < boundary) {
    collision_weight(m, share, s, beta);
    return true;
  }
  boundary_weight(m, share, boundary, beta);
  return false;
}

}  // namespace

Rgb single_scattering(const World& w, const SurfacePoint& p, const Vec3d& w_o, Random& random,
                      WalkCounts& counts) {
  Vec3d n = p.n;
  if (!(w_o.dot(n) > 0)) n = p.ng;
  const double cos_o = w_o.dot(n);
  if (!(cos_o > 0) || !(w.medium.sigma_t.maxCoeff() > 0)) return Rgb::Zero();
  Vec3d t;
  if (!refract(-w_o, n, w.eta, t) || !(t.dot(p.ng) < 0)) return Rgb::Zero();
  const double along = w.boundary.epsilon() / std::max(std::abs(t.dot(p.ng)), 0.01);
  const auto far = w.boundary.hit(p.x + along * t, t);
  if (!far) return Rgb::Zero();
  Rgb beta = Rgb::Ones();
  double s = 0;
  if (!free_path(w.medium, Rgb::Constant(1.0 / 3), along + far->t, random, beta, s)) {
    return Rgb::Zero();  // no collision before the far side
  }
  const Vec3d x = p.x + s * t;
  const double transmitted = 1 - materials::fresnel_reflectance(cos_o, w.eta);
  return transmitted / (w.eta * w.eta) * beta * next_event(w, x, -t, random, counts, nullptr);
}

MediumRgb medium_of(const materials::Material& material, double& eta) {
  MediumRgb medium;
  eta = material.medium(0).eta;
  for (int c = 0; c < 3; ++c) {
    const materials::Medium<double> m = material.medium(c);
    if (std::abs(m.eta - eta) > 1e-12) {
      throw Error("pathtrace: the channels' refractive indices differ (" + std::to_string(m.eta) +
                  " and " + std::to_string(eta) + ")");
    }
    medium.sigma_s[c] = m.sigma_s;
    medium.sigma_t[c] = m.sigma_a + m.sigma_s;
    medium.phase[std::size_t(c)].g = m.g;
  }
  medium.one_phase =
      medium.phase[0].g == medium.phase[1].g && medium.phase[0].g == medium.phase[2].g;
  return medium;
}

std::vector<Rgb> channel_groups(const MediumRgb& medium) {
  std::array<int, 3> order{0, 1, 2};
  std::sort(order.begin(), order.end(),
            [&](int a, int b) { return medium.sigma_t[a] < medium.sigma_t[b]; });
  const auto spread = [&](int a, int b) {
    // While both carry weight: the shares follow the throughputs, so once the shorter-lived channel
    // has faded the other is sampled by its own sigma_t (a weight of its albedo).
    const double albedo = std::min(medium.sigma_s[a] / std::max(medium.sigma_t[a], 1e-300),
                                   medium.sigma_s[b] / std::max(medium.sigma_t[b], 1e-300));
    const double collisions = 1 / std::max(1 - albedo, 1e-6);
    const double ratio =
        std::log(std::max(medium.sigma_t[a], 1e-300) / std::max(medium.sigma_t[b], 1e-300));
    return collisions * ratio * ratio;
  };
  std::vector<Rgb> groups;
  for (const int c : order) {
    bool placed = false;
    for (Rgb& g : groups) {
      bool fits = true;
      for (int k = 0; k < 3; ++k)
        if (g[k] > 0 && spread(c, k) >= 2) fits = false;
      if (fits) {
        g[c] = 1;
        placed = true;
        break;
      }
    }
    if (!placed) {
      groups.push_back(Rgb::Zero());
      groups.back()[c] = 1;
    }
  }
  return groups;
}

namespace {

// A path's state between its stages.
struct PathState {
  Rgb radiance = Rgb::Zero(), beta;
  Vec3d o, d;
  bool inside = false;
  bool first_surface = true;  // the camera ray has not met the boundary yet
  bool scattered = false;     // a collision happened
  int chain = 0;              // boundary events since the last collision
  double phase_pdf = 0;       // density of d at the last collision (per sr, the mixture's)
  Vec3d last;                 // the last collision
  int collisions = 0;
  // Inside, a ray starts a little off the surface point it left (so as not to hit its own face
  // again), `head` mm along itself: free paths are measured from the surface point, so the thin
  // layer skipped by the offset still holds collisions (an optical depth of 1e-3 at sigma_t = 1
  // mm^-1 in a 100 mm object otherwise lost: 0.6% of Chandrasekhar's reflection at sigma_t = 10).
  double head = 0;

  void step_in(const Boundary& boundary, const SurfacePoint& p) {
    head = boundary.epsilon() / std::max(std::abs(d.dot(p.ng)), 0.01);
    o = p.x + head * d;
  }
};

// Outside: area emitters on the way (they do not block: the camera does not see them directly).
void add_area_emitters(const World& w, PathState& p, const std::optional<SurfacePoint>& hit) {
  double t_light = 0;
  const int a = hit_area_emitter(w.lights, p.o, p.d, hit ? hit->t : 1e300, t_light);
  if (a < 0 || !(p.scattered || p.chain > 0)) return;
  const AreaEmitter& e = w.lights.area[std::size_t(a)];
  double weight = 1;
  if (p.scattered && w.matched) {  // straight from the last collision: MIS with its NEE
    const Vec3d y = p.o + t_light * p.d;
    const double distance = (y - p.last).norm();
    const double p_light = distance * distance / (-p.d.dot(e.normal) * e.area);
    weight = balance(p.phase_pdf, p_light);
  } else if (p.scattered && p.chain == 1) {
    weight = 0;  // collision, refraction out, light: the refracted connection's path
  }
  p.radiance += p.beta * weight * e.radiance.array();
}

// Outside, leaving the scene: what the camera sees behind, or the environment's light.
void add_escape(const World& w, PathState& p) {
  if (!p.scattered) {
    p.radiance += p.beta * w.lights.background(p.d);
  } else if (w.lights.environment) {
    double weight = 1;
    if (w.matched && w.lights.environment_sampler) {
      weight = balance(p.phase_pdf, w.lights.environment_sampler->pdf(p.d.cast<float>()));
    }
    p.radiance += p.beta * weight * w.lights.background(p.d);
  }
}

// Outside, at the boundary: Fresnel reflection or refraction in. False when the path ends.
bool enter(const World& w, PathState& p, const SurfacePoint& hit, Random& random) {
  Vec3d n = hit.n;
  if (!(-p.d.dot(n) > 0)) n = hit.ng;  // the interpolated normal faces away: the face's
  const double R = materials::fresnel_reflectance(-p.d.dot(n), w.eta);
  Vec3d t;
  const bool can_refract = refract(p.d, n, w.eta, t) && t.dot(hit.ng) < 0;
  ++p.chain;
  if (p.first_surface && !w.specular) {
    p.beta *= 1 - R;  // the camera's own reflection removed
  } else if (!can_refract || random.uniform() < R) {
    p.d = reflect(p.d, n);
    if (p.d.dot(hit.ng) < 0) p.d = reflect(p.d, hit.ng);  // grazing: keep it outside
    p.first_surface = false;
    p.o = w.boundary.offset(hit, p.d);
    return true;
  }
  p.first_surface = false;
  if (!can_refract) return false;
  // Radiance scales by (n_outside / n_inside)^2 into the medium, and back on the way out: a path
  // that leaves again carries 1; a next-event estimate inside (energy per area) 1 / eta^2.
  p.beta /= w.eta * w.eta;
  p.d = t;
  p.inside = true;
  p.step_in(w.boundary, hit);
  return true;
}

// Inside, a collision at x: next-event estimates, roulette, a turn. False when the path ends.
bool collide(const World& w, PathState& p, const Vec3d& x, Random& random, WalkCounts& counts) {
  const MediumRgb& m = w.medium;
  if (++p.collisions > w.options.max_collisions) {
    ++counts.truncated;
    return false;
  }
  ++counts.collisions;
  p.scattered = true;
  p.chain = 0;
  p.last = x;
  const Rgb share = shares_of(p.beta);
  p.radiance += p.beta * next_event(w, x, -p.d, random, counts, &share);
  const double top = p.beta.maxCoeff();
  if (top < kRouletteBelow) {
    if (random.uniform() * kRouletteBelow >= top) return false;
    p.beta *= kRouletteBelow / top;
  }
  // The turn: from the one phase, or from a channel's picked by its share (the mixture's density
  // divides each channel's own).
  const int k = m.one_phase ? 0 : pick_channel(share, random.uniform());
  const Vec3d turned = m.phase[std::size_t(k)].sample(p.d, random.uniform(), random.uniform());
  const double cos_turn = turned.dot(p.d);
  p.phase_pdf = mixture_phase_pdf(m, share, cos_turn);
  if (!m.one_phase) p.beta *= m.phase_pdf(cos_turn) / p.phase_pdf;
  p.d = turned;
  p.o = x;
  p.head = 0;
  return true;
}

// Inside, at the boundary: internal reflection (total beyond the critical angle) or out.
void leave(const World& w, PathState& p, const SurfacePoint& hit, Random& random) {
  ++p.chain;
  Vec3d n = hit.n;
  if (!(p.d.dot(n) > 0)) n = hit.ng;
  const double R = materials::fresnel_reflectance(p.d.dot(n), 1 / w.eta);
  Vec3d t;
  const bool can_refract = refract(p.d, -n, 1 / w.eta, t) && t.dot(hit.ng) > 0;
  if (!can_refract || random.uniform() < R) {
    p.d = reflect(p.d, n);
    if (p.d.dot(hit.ng) > 0) p.d = reflect(p.d, hit.ng);
    p.step_in(w.boundary, hit);
    return;
  }
  p.beta *= w.eta * w.eta;
  p.d = t;
  p.inside = false;
  p.o = w.boundary.offset(hit, p.d);
}

}  // namespace

Rgb trace_path(const World& w, const Vec3d& eye, const Vec3d& direction, const Rgb& carried,
               Random& random, WalkCounts& counts) {
  ++counts.paths;
  PathState p;
  p.beta = carried;
  p.o = p.last = eye;
  p.d = direction;
  for (;;) {
    if (p.inside) {
      // The free path first: most end inside, where an occlusion query over the segment (which
      // stops at its end) costs less than finding the boundary beyond it.
      const Rgb share = shares_of(p.beta);
      const double s = draw_free_path(w.medium, share, random);
      if (std::isfinite(s) && s > p.head && !w.boundary.occluded(p.o, p.d, s - p.head)) {
        collision_weight(w.medium, share, s, p.beta);
        if (!collide(w, p, p.o + (s - p.head) * p.d, random, counts)) return p.radiance;
        continue;
      }
      const auto hit = w.boundary.hit(p.o, p.d);
      if (!hit || p.d.dot(hit->ng) < 0) {  // no way out, or a face seen from inside: a leak
        ++counts.leaks;
        return p.radiance;
      }
      if (s < p.head + hit->t) {  // the query and the hit disagree by rounding at the end
        collision_weight(w.medium, share, s, p.beta);
        if (!collide(w, p, p.o + (s - p.head) * p.d, random, counts)) return p.radiance;
        continue;
      }
      boundary_weight(w.medium, share, p.head + hit->t, p.beta);
      leave(w, p, *hit, random);
      continue;
    }
    const auto hit = w.boundary.hit(p.o, p.d);
    add_area_emitters(w, p, hit);
    if (!hit) {
      add_escape(w, p);
      return p.radiance;
    }
    if (p.d.dot(hit->ng) > 0) {  // the inside of the mesh, seen from outside: an open mesh
      ++counts.leaks;
      return p.radiance;
    }
    if (!enter(w, p, *hit, random)) return p.radiance;
  }
}

}  // namespace lucent::render::pathtrace
