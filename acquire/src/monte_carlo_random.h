// The random numbers of lucent's Monte Carlo codes (the capture simulator and the transport
// tables): xoshiro256** streams seeded by splitmix64, and an exact ziggurat for exponential free
// paths. Shared so that both codes draw the same kind of streams; internal to lucent_acquire.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>

namespace lucent::acquire::detail {

// ---------------------------------------------------------------------------------------------
// Random numbers: xoshiro256** (Blackman and Vigna 2018), seeded by splitmix64.

inline std::uint64_t splitmix64_next(std::uint64_t& state) {
  std::uint64_t z = (state += 0x9e3779b97f4a7c15ULL);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

inline std::uint64_t mix64(std::uint64_t value) {
  return splitmix64_next(value);
}

class Xoshiro256StarStar {
 public:
  explicit Xoshiro256StarStar(std::uint64_t seed) {
    for (auto& word : s_) word = splitmix64_next(seed);
  }

  std::uint64_t next() {
    const std::uint64_t result = rotl(s_[1] * 5, 7) * 9;
    const std::uint64_t t = s_[1] << 17;
    s_[2] ^= s_[0];
    s_[3] ^= s_[1];
    s_[1] ^= s_[2];
    s_[0] ^= s_[3];
    s_[2] ^= t;
    s_[3] = rotl(s_[3], 45);
    return result;
  }

  /// Uniform in [0, 1), 53 random bits.
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }
  /// Uniform in (0, 1): safe for log.
  double uniform_open() { return (static_cast<double>(next() >> 11) + 0.5) * 0x1.0p-53; }

 private:
  static std::uint64_t rotl(std::uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }
  std::uint64_t s_[4];
};

/// Standard exponential variates by Marsaglia and Tsang's ziggurat (2000), 256 layers of equal area
/// v under e^-x: ~99% of draws cost one random number, a multiply and a compare, against a log for
/// inversion (a quarter of the transport time in profiles). Exact: the wedges are sampled by
/// rejection against e^-x and the tail beyond r by r + Exp(1) (memorylessness).
class ExponentialZiggurat {
 public:
  ExponentialZiggurat() {
    // Layer 0 is the base strip [0, x_0] x [0, e^-r] holding the tail too (x_0 = v / e^-r); layer
    // i >= 1 is [0, x_i] x [e^-x_i, e^-x_(i+1)], each of area v.
    constexpr double r = 7.69711747013104972;
    constexpr double v = 3.949659822581572e-3;
    x_[0] = v / std::exp(-r);
    x_[1] = r;
    for (int i = 1; i < kLayers - 1; ++i) x_[i + 1] = -std::log(v / x_[i] + std::exp(-x_[i]));
    x_[kLayers] = 0;
    for (int i = 0; i <= kLayers; ++i) f_[i] = std::exp(-x_[i]);
  }

  double sample(Xoshiro256StarStar& rng) const {
    for (;;) {
      const std::uint64_t bits = rng.next();
      const auto i = static_cast<int>(bits & (kLayers - 1));  // low 8 bits: the layer
      // High 53 bits: the position, at the centre of its cell so that x > 0 (an infinite mean free
      // path, sigma_t = 0, then gives an infinite free path, never 0 * inf).
      const double u = (static_cast<double>(bits >> 11) + 0.5) * 0x1.0p-53;
      const double x = u * x_[i];
      if (x < x_[i + 1]) return x;  // wholly under the curve
      if (i == 0) return x_[1] - std::log(rng.uniform_open());
      if (f_[i] + rng.uniform() * (f_[i + 1] - f_[i]) < std::exp(-x)) return x;
    }
  }

 private:
  static constexpr int kLayers = 256;
  double x_[kLayers + 1];
  double f_[kLayers + 1];
};

inline const ExponentialZiggurat& exponential_ziggurat() {
  static const ExponentialZiggurat table;
  return table;
}

inline std::uint64_t stream_seed(std::uint64_t seed, int channel, std::uint64_t batch) {
  std::uint64_t h = mix64(seed ^ 0x6c7563656e74ULL);  // "lucent"
  h = mix64(h + static_cast<std::uint64_t>(channel) + 1);
  return mix64(h ^ (batch * 0xd1342543de82ef95ULL + 1));
}

/// A uniform point (a, b) in the unit disc by rejection from the square, both coordinates from one
/// 64-bit draw (32 bits each: a resolution of 5e-10, far below anything a direction needs).
inline double sample_unit_disc(Xoshiro256StarStar& rng, double& a, double& b) {
  for (;;) {
    const std::uint64_t bits = rng.next();
    a = static_cast<double>(static_cast<std::int32_t>(bits >> 32)) * 0x1.0p-31;
    b = static_cast<double>(static_cast<std::int32_t>(bits & 0xffffffffu)) * 0x1.0p-31;
    const double r2 = a * a + b * b;
    if (r2 < 1) return r2;
  }
}

/// cos and sin of a uniform azimuth without trigonometry, rejection or division (the unit disc's
/// rejection is a mispredicted branch a fifth of the time: a Henyey-Greenstein scattering took
/// 1.4x as long that way in a micro-benchmark here): the top 10 bits of
/// one draw pick one of 1,024 sectors, whose cosine and sine are tabulated; the other 54 bits place
/// the angle within it, delta < 2 pi / 1024 = 6.1e-3, and turn the sector's edge by delta through
/// the Taylor series of cos and sin to delta^6 and delta^7 (next terms below 1e-22: exact to
/// rounding).
class AzimuthTable {
 public:
  AzimuthTable() {
    for (int i = 0; i < kSectors; ++i) {
      const double angle = 2 * std::numbers::pi * i / kSectors;
      cos_[i] = std::cos(angle);
      sin_[i] = std::sin(angle);
    }
  }

  void sample(std::uint64_t bits, double& cos_phi, double& sin_phi) const {
    const auto i = static_cast<int>(bits >> (64 - kBits));
    constexpr std::uint64_t kMask = (std::uint64_t{1} << (64 - kBits)) - 1;
    constexpr double kStep = 2 * std::numbers::pi / kSectors * 0x1.0p-54;  // 2^(64 - kBits)
    const double delta = static_cast<double>(bits & kMask) * kStep;
    const double d2 = delta * delta;
    const double c = 1 - d2 * (1.0 / 2 - d2 * (1.0 / 24 - d2 * (1.0 / 720)));
    const double s = delta * (1 - d2 * (1.0 / 6 - d2 * (1.0 / 120 - d2 * (1.0 / 5040))));
    cos_phi = cos_[i] * c - sin_[i] * s;
    sin_phi = sin_[i] * c + cos_[i] * s;
  }

 private:
  static constexpr int kBits = 10;
  static constexpr int kSectors = 1 << kBits;
  static_assert(64 - kBits == 54);
  double cos_[kSectors];
  double sin_[kSectors];
};

inline const AzimuthTable& azimuth_table() {
  static const AzimuthTable table;
  return table;
}

/// cos(phi), sin(phi) of a uniform azimuth.
inline void sample_azimuth(Xoshiro256StarStar& rng, double& cos_phi, double& sin_phi) {
  azimuth_table().sample(rng.next(), cos_phi, sin_phi);
}

/// A uniform direction on the sphere (Marsaglia 1972): from (a, b) uniform in the unit disc with
/// r2 = a^2 + b^2, (2 a sqrt(1 - r2), 2 b sqrt(1 - r2), 1 - 2 r2). One square root, no division.
inline void sample_isotropic(Xoshiro256StarStar& rng, double& ux, double& uy, double& uz) {
  double a, b;
  const double r2 = sample_unit_disc(rng, a, b);
  const double scale = 2 * std::sqrt(1 - r2);
  ux = a * scale;
  uy = b * scale;
  uz = 1 - 2 * r2;
}

/// Henyey-Greenstein constants for one g.
struct HenyeyGreenstein {
  double g = 0;
  double one_plus_g2 = 1, one_minus_g2 = 1, inv_2g = 0,
         pdf_scale = 1 / (4 * 3.14159265358979323846);
  explicit HenyeyGreenstein(double g_ = 0)
      : g(g_),
        one_plus_g2(1 + g_ * g_),
        one_minus_g2(1 - g_ * g_),
        inv_2g(g_ != 0 ? 1.0 / (2 * g_) : 0.0),
        pdf_scale((1 - g_ * g_) / (4 * 3.14159265358979323846)) {}
  /// Phase function value (per sr) for the cosine between the old and new directions.
  double pdf(double cos_theta) const {
    const double denom = one_plus_g2 - 2 * g * cos_theta;
    return pdf_scale / (denom * std::sqrt(denom));
  }
};

/// Turns the unit direction (ux, uy, uz) by a Henyey-Greenstein deflection (inversion as in MCML,
/// guarded against rounding past +-1) and a uniform azimuth. For |g| < 1e-6 the inversion formula
/// is singular (0/0): a uniform direction on the sphere instead.
[[gnu::always_inline]] inline void scatter_henyey_greenstein(const HenyeyGreenstein& hg,
                                                             Xoshiro256StarStar& rng, double& ux,
                                                             double& uy, double& uz) {
  if (std::abs(hg.g) < 1e-6) {
    sample_isotropic(rng, ux, uy, uz);
    return;
  }
  double cos_phi, sin_phi;
  const double tmp = hg.one_minus_g2 / (1 - hg.g + 2 * hg.g * rng.uniform());
  const double cos_theta = std::clamp((hg.one_plus_g2 - tmp * tmp) * hg.inv_2g, -1.0, 1.0);
  const double sin_theta = std::sqrt(std::max(0.0, 1 - cos_theta * cos_theta));
  sample_azimuth(rng, cos_phi, sin_phi);
  if (std::abs(uz) > 0.99999) {
    // Near the pole the general rotation divides by ~0 (MCML's Spin()).
    ux = sin_theta * cos_phi;
    uy = sin_theta * sin_phi;
    uz = uz > 0 ? cos_theta : -cos_theta;
  } else {
    const double root = std::sqrt(1 - uz * uz);
    const double nx = sin_theta * (ux * uz * cos_phi - uy * sin_phi) / root + ux * cos_theta;
    const double ny = sin_theta * (uy * uz * cos_phi + ux * sin_phi) / root + uy * cos_theta;
    const double nz = -sin_theta * cos_phi * root + uz * cos_theta;
    ux = nx;
    uy = ny;
    uz = nz;
  }
}

}  // namespace lucent::acquire::detail
