// Beyond Klotzli & Olano (an extension of ours): a fur coat over a translucent mesh (peach fuzz,
// velvet, hairy skin). The hairs above the skin shadow the light that enters it; the BSSRDF then
// spreads that light over a mean free path or more, far wider than a hair, so what reaches the
// profile is the coat's transmittance averaged over the skin's texels and the light's azimuth,
//
//   T(mu) = < T(p, d) >,  p on the bottom shell, d at cos theta = mu to the normal (fur.h eq. 4),
//
// a function of the light's elevation alone. The maps and the reference multiply each light
// sample's transmitted irradiance by T(n . w_i) (the Fresnel factor's neighbour); the shells drawn
// over the mesh by `--technique fur` add the view side (their alpha) and the hairs' own light.
//
// Stored at mu_k = (k + 1) / n, k = 0..n-1, interpolated as ln T linear in 1 / mu (exact for a
// homogeneous coat, T = exp(-tau / mu)) and extrapolated that way below mu_0 (T -> 0 at grazing
// light: an endless grazing path meets a hair; a coat without hairs stays at 1).
#pragma once

#include <cmath>
#include <vector>

namespace lucent::render {

struct FurCoat {
  std::vector<float> transmittance;  ///< T(mu_k), mu_k = (k + 1) / n (the file comment), n >= 2

  /// T(mu), mu = cos theta of the light to the shading normal; 0 for mu <= 0.
  template <typename T>
  T at(T mu) const {
    const int n = int(transmittance.size());
    if (n < 2) return n == 1 ? T(transmittance[0]) : T(1);  // not a table: a constant, or no coat
    if (!(mu > T(0))) return T(0);
    if (mu >= T(1)) return T(transmittance[std::size_t(n - 1)]);
    int k = int(mu * T(n)) - 1;  // mu_k <= mu < mu_k+1
    k = k < 0 ? 0 : (k > n - 2 ? n - 2 : k);
    const T a = T(transmittance[std::size_t(k)]), b = T(transmittance[std::size_t(k + 1)]);
    const T inv_a = T(n) / T(k + 1), inv_b = T(n) / T(k + 2);
    const T t = (T(1) / mu - inv_a) / (inv_b - inv_a);
    T v;
    if (a > T(0) && b > T(0)) {
      v = std::exp(std::log(a) + t * (std::log(b) - std::log(a)));
    } else {
      v = a + t * (b - a);  // opaque at a node: linear
    }
    return v > T(0) ? (v < T(1) ? v : T(1)) : T(0);
  }
};

}  // namespace lucent::render
