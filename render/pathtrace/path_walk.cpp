// One channel's path (path_walk.h): from the camera through the boundary's Fresnel events into the
// medium, collision after collision (free paths drawn from sigma_t, Henyey-Greenstein turns), with
// next-event estimates of every light at every collision, until it leaves the scene or roulette
// ends it.
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

// A delta light straight through an invisible boundary: phase x irradiance x transmittance.
double straight_delta(const World& w, const Channel& ch, const Light& light, const Vec3d& x,
                      const Vec3d& toward) {
  Vec3d to_light;
  double distance = std::numeric_limits<double>::infinity(), falloff = 1;
  if (light.type == LightType::kDirectional) {
    to_light = light.direction.cast<double>().normalized();
  } else {
    to_light = light.position.cast<double>() - x;
    distance = to_light.norm();
    if (!(distance > 0)) return 0;
    to_light /= distance;
    falloff = 1 / (distance * distance);
  }
  const double tau = ch.sigma_t * inside_length(w.boundary, x, to_light, distance);
  return ch.phase.pdf(-to_light.dot(toward)) * falloff * std::exp(-tau);
}

}  // namespace

double next_event(const World& w, int c, const Vec3d& x, const Vec3d& toward, Random& random,
                  WalkCounts& counts, bool escapes) {
  const auto share = [escapes](double mine, double other) {
    return escapes ? balance(mine, other) : 1.0;
  };
  const Channel& ch = w.channel[std::size_t(c)];
  double sum = 0;
  for (const Light& light : w.lights.delta) {
    const double value = light.radiance[c];
    if (!(value > 0)) continue;
    if (w.matched) {
      sum += value * straight_delta(w, ch, light, x, toward);
      continue;
    }
    Connection link;
    const Link outcome = refracted_connection(w, light, x, link);
    counts.count(int(outcome));
    if (outcome == Link::kConnected) {
      sum += value * ch.phase.pdf(link.travel.dot(toward)) * link.irradiance *
             std::exp(-ch.sigma_t * link.distance);
    }
  }
  for (const AreaEmitter& e : w.lights.area) {
    const double value = e.radiance[c];
    if (!(value > 0)) continue;
    const Vec3d y = sample_area(e, random);
    if (w.matched) {
      Vec3d to_light = y - x;
      const double distance = to_light.norm();
      to_light /= distance;
      const double cos_light = -to_light.dot(e.normal);
      if (!(cos_light > 0)) continue;
      const double tau = ch.sigma_t * inside_length(w.boundary, x, to_light, distance);
      const double p_light = distance * distance / (cos_light * e.area);  // per sr
      const double phase = ch.phase.pdf(-to_light.dot(toward));
      sum += value * phase * std::exp(-tau) / p_light * share(p_light, phase);
      continue;
    }
    // Through the refracting boundary: the point y as a point light of intensity L cos A.
    Light point;
    point.type = LightType::kPoint;
    point.position = y.cast<float>();
    Connection link;
    const Link outcome = refracted_connection(w, point, x, link);
    counts.count(int(outcome));
    if (outcome == Link::kConnected) {
      const double cos_light = (link.exit - y).normalized().dot(e.normal);
      if (cos_light > 0) {
        sum += value * cos_light * e.area * ch.phase.pdf(link.travel.dot(toward)) *
               link.irradiance * std::exp(-ch.sigma_t * link.distance);
      }
    }
  }
  if (w.matched && w.lights.environment_sampler && !w.lights.environment_sampler->black()) {
    double pdf = 0;
    const Vec3d dir = w.lights.environment_sampler->sample(random.uniform(), random.uniform(), pdf)
                          .cast<double>();
    if (pdf > 0) {
      const double tau =
          ch.sigma_t * inside_length(w.boundary, x, dir, std::numeric_limits<double>::infinity());
      const double phase = ch.phase.pdf(-dir.dot(toward));
      sum += w.lights.background(dir, c) * phase * std::exp(-tau) / pdf * share(pdf, phase);
    }
  }
  return sum;
}

double single_scattering(const World& w, int c, const SurfacePoint& p, const Vec3d& w_o,
                         Random& random, WalkCounts& counts) {
  const Channel& ch = w.channel[std::size_t(c)];
  Vec3d n = p.n;
  if (!(w_o.dot(n) > 0)) n = p.ng;
  const double cos_o = w_o.dot(n);
  if (!(cos_o > 0) || !(ch.sigma_t > 0)) return 0;
  Vec3d t;
  if (!refract(-w_o, n, w.eta, t) || !(t.dot(p.ng) < 0)) return 0;
  const double along = w.boundary.epsilon() / std::max(std::abs(t.dot(p.ng)), 0.01);
  const auto far = w.boundary.hit(p.x + along * t, t);
  if (!far) return 0;
  const double s = -std::log(1 - random.uniform()) / ch.sigma_t;
  if (s >= along + far->t) return 0;  // no collision before the far side
  const Vec3d x = p.x + s * t;
  const double transmitted = 1 - materials::fresnel_reflectance(cos_o, w.eta);
  return transmitted / (w.eta * w.eta) * ch.albedo *
         next_event(w, c, x, -t, random, counts, false);
}

std::array<Channel, 3> channels_of(const materials::Material& material, double& eta) {
  std::array<Channel, 3> channels;
  eta = material.medium(0).eta;
  for (int c = 0; c < 3; ++c) {
    const materials::Medium<double> m = material.medium(c);
    if (std::abs(m.eta - eta) > 1e-12) {
      throw Error("pathtrace: the channels' refractive indices differ (" + std::to_string(m.eta) +
                  " and " + std::to_string(eta) + ")");
    }
    Channel& ch = channels[std::size_t(c)];
    ch.sigma_s = m.sigma_s;
    ch.sigma_t = m.sigma_a + m.sigma_s;
    ch.albedo = ch.sigma_t > 0 ? m.sigma_s / ch.sigma_t : 0;
    ch.phase.g = m.g;
  }
  return channels;
}

double trace_path(const World& w, int c, const Vec3d& eye, const Vec3d& direction, Random& random,
                  WalkCounts& counts) {
  const Channel& ch = w.channel[std::size_t(c)];
  const Boundary& boundary = w.boundary;
  ++counts.paths;
  double radiance = 0, beta = 1;
  Vec3d o = eye, d = direction;
  bool inside = false;
  bool first_surface = true;  // the camera ray has not met the boundary yet
  bool scattered = false;     // a collision happened
  int chain = 0;              // boundary events since the last collision
  double phase_pdf = 0;       // density of d at the last collision (per sr)
  Vec3d last = eye;           // the last collision
  int collisions = 0;
  // Inside, a ray starts a little off the surface point it left (so as not to hit its own face
  // again), `head` mm along itself: free paths are measured from the surface point, so the thin
  // layer skipped by the offset still holds collisions (an optical depth of 1e-3 at sigma_t = 1
  // mm^-1 in a 100 mm object otherwise lost: 0.6% of Chandrasekhar's reflection at sigma_t = 10).
  double head = 0;
  const auto step_in = [&](const SurfacePoint& p, const Vec3d& dir, double& along) {
    along = boundary.epsilon() / std::max(std::abs(dir.dot(p.ng)), 0.01);
    return Vec3d(p.x + along * dir);
  };

  for (;;) {
    const auto hit = boundary.hit(o, d);
    if (!inside) {
      // Area emitters on the way (they do not block: the camera does not see them directly).
      double t_light = 0;
      const int a = hit_area_emitter(w.lights, o, d, hit ? hit->t : 1e300, t_light);
      if (a >= 0 && (scattered || chain > 0)) {
        const AreaEmitter& e = w.lights.area[std::size_t(a)];
        double weight = 1;
        if (scattered && w.matched) {  // straight from the last collision: MIS with its NEE
          const Vec3d y = o + t_light * d;
          const double distance = (y - last).norm();
          const double p_light = distance * distance / (-d.dot(e.normal) * e.area);
          weight = balance(phase_pdf, p_light);
        } else if (scattered && chain == 1) {
          weight = 0;  // collision, refraction out, light: the refracted connection's path
        }
        radiance += beta * weight * e.radiance[c];
      }
      if (!hit) {
        if (!scattered) {
          radiance += beta * w.lights.background(d, c);  // what the camera sees behind
        } else if (w.lights.environment) {
          double weight = 1;
          if (w.matched && w.lights.environment_sampler) {
            weight = balance(phase_pdf, w.lights.environment_sampler->pdf(d.cast<float>()));
          }
          radiance += beta * weight * w.lights.background(d, c);
        }
        return radiance;
      }
      if (d.dot(hit->ng) > 0) {  // the inside of the mesh, seen from outside: an open mesh
        ++counts.leaks;
        return radiance;
      }
      // Entering: Fresnel reflection or refraction.
      Vec3d n = hit->n;
      if (!(-d.dot(n) > 0)) n = hit->ng;  // the interpolated normal faces away: the face's
      const double R = materials::fresnel_reflectance(-d.dot(n), w.eta);
      Vec3d t;
      const bool can_refract = refract(d, n, w.eta, t) && t.dot(hit->ng) < 0;
      ++chain;
      if (first_surface && !w.specular) {
        beta *= 1 - R;  // the camera's own reflection removed
      } else if (!can_refract || random.uniform() < R) {
        d = reflect(d, n);
        if (d.dot(hit->ng) < 0) d = reflect(d, hit->ng);  // grazing: keep it outside
        first_surface = false;
        o = boundary.offset(*hit, d);
        continue;
      }
      first_surface = false;
      if (!can_refract) return radiance;
      // Radiance scales by (n_outside / n_inside)^2 into the medium, and back on the way out: a
      // path that leaves again carries 1; a next-event estimate inside (energy per area) 1 / eta^2.
      beta /= w.eta * w.eta;
      d = t;
      inside = true;
      o = step_in(*hit, d, head);
      continue;
    }

    if (!hit || d.dot(hit->ng) < 0) {  // no way out, or a face seen from inside: a leak
      ++counts.leaks;
      return radiance;
    }
    const double s = ch.sigma_t > 0 ? -std::log(1 - random.uniform()) / ch.sigma_t
                                    : std::numeric_limits<double>::infinity();
    if (s < head + hit->t) {
      // A collision: next-event estimates, then absorption (as weight) and a turn.
      const Vec3d x = o + (s - head) * d;
      if (++collisions > w.options.max_collisions) {
        ++counts.truncated;
        return radiance;
      }
      ++counts.collisions;
      scattered = true;
      chain = 0;
      last = x;
      radiance += beta * ch.albedo * next_event(w, c, x, -d, random, counts);
      beta *= ch.albedo;
      if (beta < kRouletteBelow) {
        if (random.uniform() * kRouletteBelow >= beta) return radiance;
        beta = kRouletteBelow;
      }
      const Vec3d turned = ch.phase.sample(d, random.uniform(), random.uniform());
      phase_pdf = ch.phase.pdf(turned.dot(d));
      d = turned;
      o = x;
      head = 0;
      continue;
    }
    // The boundary from inside: internal reflection (total beyond the critical angle) or out.
    ++chain;
    Vec3d n = hit->n;
    if (!(d.dot(n) > 0)) n = hit->ng;
    const double R = materials::fresnel_reflectance(d.dot(n), 1 / w.eta);
    Vec3d t;
    const bool can_refract = refract(d, -n, 1 / w.eta, t) && t.dot(hit->ng) > 0;
    if (!can_refract || random.uniform() < R) {
      d = reflect(d, n);
      if (d.dot(hit->ng) > 0) d = reflect(d, hit->ng);
      o = step_in(*hit, d, head);
      continue;
    }
    beta *= w.eta * w.eta;
    d = t;
    inside = false;
    o = boundary.offset(*hit, d);
  }
}

}  // namespace lucent::render::pathtrace
