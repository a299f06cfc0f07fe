// The tabulated model's preparation of a table (tabulated.h).
#include "lucent/materials/tabulated.h"

#include <algorithm>
#include <limits>
#include <cmath>
#include <map>
#include <mutex>
#include <tuple>
#include <random>
#include <sstream>

#include "lucent/core/error.h"
#include "lucent/materials/oblique.h"

namespace lucent::materials {
namespace detail {

// Annulus averages -> point values at the bins' log centres. The file holds what Monte Carlo
// measures, the mean over each annulus; the interpolant needs point values, and in a steep far
// field (log value falling by ~sigma_tr rho, tens across a decade) the two differ by far more than
// a second-order correction can mend. So the point values p are found by fixed-point iteration:
// p += ln(stored average) - ln(average of the interpolant of p over the annulus), the average by
// 8-point Gauss-Legendre in r^2 (uniform in area). Four rounds bring the interpolant's averages
// to the stored ones within 1e-4 relative.
void to_point_values(std::vector<double>& f, const std::vector<double>& x,
                     const TransportTableGrid& grid) {
  static constexpr double kNode[8] = {0.0198550718, 0.1016667613, 0.2372337950, 0.4082826788,
                                      0.5917173212, 0.7627662050, 0.8983332387, 0.9801449282};
  static constexpr double kWeight[8] = {0.0506142681, 0.1111905172, 0.1568533229, 0.1813418917,
                                        0.1813418917, 0.1568533229, 0.1111905172, 0.0506142681};
  const int J = int(x.size());
  std::vector<double> p = f;
  for (int round = 0; round < 4; ++round) {
    std::vector<double> next = p;
    for (int j = 0; j < J; ++j) {
      const double r0 = grid.rho_edge(j), r1 = grid.rho_edge(j + 1);
      double avg = 0;
      for (int k = 0; k < 8; ++k) {
        const double r = std::sqrt(r0 * r0 + kNode[k] * (r1 * r1 - r0 * r0));
        avg += kWeight[k] * std::exp(interpolate_row(x, p, r) - f[std::size_t(j)]);
      }
      // Guard: an average that over- or underflows (a row that runs into the 1e-37 floor of the
      // file) leaves the value as it is.
      if (std::isfinite(avg) && avg > 0) next[std::size_t(j)] = p[std::size_t(j)] - std::log(avg);
    }
    p = next;
  }
  f = p;
}

}  // namespace detail

using detail::to_point_values;

TabulatedProfile TabulatedProfile::slab_node(const TransportTable& table, double g) {
  TransportTable semi;  // the same slices read as a semi-infinite table's (only the flag differs)
  semi.grid = table.grid;
  semi.partial = table.partial;
  semi.slices = table.slices;
  semi.source = table.source;
  return TabulatedProfile(semi, g);
}

TabulatedProfile::TabulatedProfile(const TransportTable& table, double g) : g_(g) {
  if (table.partial) throw Error(table.source + ": a partial table (merge the shards first)");
  if (table.slab())
    throw Error(table.source + ": a slab's table (" + (table.transmitted ? "far" : "lit") +
                " side): lucent fit builds and uses these for --thickness-mm; it is not a "
                "semi-infinite --table");
  if (table.grid.phi_bins != 1)
    throw Error(table.source + ": an oblique table (2D, " + std::to_string(table.grid.phi_bins) +
                " azimuths): give it as --oblique-table, not as the radial --table");
  std::map<double, std::vector<const TransportTableSlice*>> by_g;
  for (const TransportTableSlice& s : table.slices) by_g[s.g].push_back(&s);
  std::vector<double> g_nodes;
  for (auto& [gv, list] : by_g) {
    std::sort(list.begin(), list.end(), [](auto* a, auto* b) { return a->eta < b->eta; });
    g_nodes.push_back(gv);
  }
  std::ostringstream range;
  range << "[" << g_nodes.front() << ", " << g_nodes.back() << "]";
  if (!(g >= g_nodes.front() - 1e-12 && g <= g_nodes.back() + 1e-12))
    throw Error("--g: " + std::to_string(g) + " is outside the transport table's g range " +
                range.str() + " (" + table.source + "; build a wider one with lucent tabulate)");
  const auto& first = by_g.begin()->second;
  for (const TransportTableSlice* s : first) eta_.push_back(s->eta);
  for (const auto& [gv, list] : by_g) {
    bool same = list.size() == first.size();
    for (std::size_t i = 0; same && i < list.size(); ++i) same = list[i]->eta == first[i]->eta;
    if (!same)
      throw Error(table.source + ": every g of the table needs the same eta slices");
  }
  u_ = table.grid.u;
  J_ = table.grid.rho_bins();
  rho_min_ = table.grid.rho_min;
  rho_max_ = table.grid.rho_max;
  for (int j = 0; j < J_; ++j) x_.push_back(std::log(table.grid.rho_centre(j)));

  // g weights (double): a node, or the Hermite interpolant between nodes.
  const NodeWeights<double> wg = hermite_weights(g_nodes, g, false);
  const std::size_t K = u_.size(), n = K * std::size_t(J_);
  photons_ = ~std::uint64_t(0);
  for (std::size_t e = 0; e < eta_.size(); ++e) {
    std::array<std::vector<double>, kTableQuantities> f;
    std::array<std::vector<float>, kTableQuantities> se;
    std::vector<double> lt(K, 0.0), tse(K, 0.0);
    for (int q = 0; q < kTableQuantities; ++q) {
      f[std::size_t(q)].assign(n, 0.0);
      se[std::size_t(q)].assign(n, 0.0f);
    }
    for (int b = 0; b < wg.count; ++b) {
      const double w = wg.w[std::size_t(b)];
      if (w == 0) continue;
      const TransportTableSlice& s = *by_g[g_nodes[std::size_t(wg.first + b)]][e];
      photons_ = std::min(photons_, s.photons);
      for (int q = 0; q < kTableQuantities; ++q) {
        for (std::size_t k = 0; k < K; ++k) {
          const double a = 1 - u_[k] * u_[k];
          std::vector<double> row(static_cast<std::size_t>(J_));
          for (int j = 0; j < J_; ++j)
            row[std::size_t(j)] = std::log(
                std::max(double(s.value[std::size_t(q)][k * std::size_t(J_) + std::size_t(j)]),
                         1e-37) / a);
          to_point_values(row, x_, table.grid);
          for (int j = 0; j < J_; ++j) {
            const std::size_t i = k * std::size_t(J_) + std::size_t(j);
            f[std::size_t(q)][i] += w * row[std::size_t(j)];
            se[std::size_t(q)][i] = std::max(se[std::size_t(q)][i],
                                             float(decode_relative_se(s.se_code[std::size_t(q)][i])));
          }
        }
      }
      for (std::size_t k = 0; k < K; ++k) {
        const double a = 1 - u_[k] * u_[k];
        lt[k] += w * std::log(std::max(s.total[k], 1e-300) / a);
        tse[k] = std::max(tse[k], s.total[k] > 0 ? s.total_se[k] / s.total[k] : INFINITY);
      }
    }
    f_.push_back(std::move(f));
    rel_se_.push_back(std::move(se));
    log_total_.push_back(std::move(lt));
    total_rel_se_.push_back(std::move(tse));
  }
}

TabulatedProfile TabulatedProfile::at_eta(double eta) const {
  TabulatedProfile p;
  p.g_ = g_;
  p.u_ = u_;
  p.x_ = x_;
  p.J_ = J_;
  p.rho_min_ = rho_min_;
  p.rho_max_ = rho_max_;
  p.photons_ = photons_;
  p.eta_ = {eta};
  const NodeWeights<double> we = hermite_weights(eta_, eta, false);
  std::array<std::vector<double>, kTableQuantities> f;
  std::array<std::vector<float>, kTableQuantities> se;
  std::vector<double> lt(u_.size(), 0.0);
  for (int q = 0; q < kTableQuantities; ++q) {
    f[std::size_t(q)].assign(f_.front()[std::size_t(q)].size(), 0.0);
    se[std::size_t(q)].assign(f_.front()[std::size_t(q)].size(), 0.0f);
  }
  for (int a = 0; a < we.count; ++a) {
    const std::size_t s = std::size_t(we.first + a);
    const double w = we.w[std::size_t(a)];
    for (int q = 0; q < kTableQuantities; ++q) {
      for (std::size_t i = 0; i < f[std::size_t(q)].size(); ++i) {
        f[std::size_t(q)][i] += w * f_[s][std::size_t(q)][i];
        if (w != 0) se[std::size_t(q)][i] = std::max(se[std::size_t(q)][i], rel_se_[s][std::size_t(q)][i]);
      }
    }
    for (std::size_t k = 0; k < lt.size(); ++k) lt[k] += w * log_total_[s][k];
  }
  p.f_ = {std::move(f)};
  p.rel_se_ = {std::move(se)};
  p.log_total_ = {std::move(lt)};
  std::vector<double> tse(u_.size(), 0.0);
  for (int a = 0; a < we.count; ++a)
    if (we.w[std::size_t(a)] != 0)
      for (std::size_t k = 0; k < tse.size(); ++k)
        tse[k] = std::max(tse[k], total_rel_se_[std::size_t(we.first + a)][k]);
  p.total_rel_se_ = {std::move(tse)};
  return p;
}

TabulatedProfile TabulatedProfile::with_oblique(std::shared_ptr<const ObliqueProfile> o) const {
  TabulatedProfile p = *this;
  p.oblique_ = std::move(o);
  return p;
}

TabulatedProfile TabulatedProfile::with_slab(std::shared_ptr<const SlabNodes> slab) const {
  TabulatedProfile p = *this;
  p.slab_ = std::move(slab);
  return p;
}

TabulatedProfile TabulatedProfile::perturbed(std::uint64_t seed) const {
  TabulatedProfile p = *this;
  if (oblique_) p.oblique_ = std::make_shared<const ObliqueProfile>(oblique_->perturbed(seed + 7919));
  if (slab_) {
    // Each node its own realisation of its noise (the nodes are independent runs).
    auto slab = std::make_shared<SlabNodes>(*slab_);
    std::uint64_t k = 0;
    for (auto* list : {&slab->reflected, &slab->transmitted})
      for (TabulatedProfile& node : *list) node = node.perturbed(seed + 104729 * ++k);
    p.slab_ = std::move(slab);
  }
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (std::size_t s = 0; s < p.f_.size(); ++s) {
    for (int q = 0; q < kTableQuantities; ++q) {
      std::vector<double>& f = p.f_[s][std::size_t(q)];
      const std::vector<float>& se = p.rel_se_[s][std::size_t(q)];
      for (std::size_t i = 0; i < f.size(); ++i) {
        const double draw = normal(rng);  // drawn for every entry: the stream does not depend on
        if (std::isfinite(se[i])) f[i] += draw * std::min(double(se[i]), 1.0);  // which are finite
      }
    }
  }
  return p;
}

double TabulatedProfile::relative_se(TableQuantity q, double rho, double alpha_prime, double eta,
                                     double thickness_s, bool transmitted) const {
  if (!slab_ || !(thickness_s < std::numeric_limits<double>::infinity()))
    return relative_se(q, rho, alpha_prime, eta);
  const std::vector<double>& x =
      transmitted ? slab_->log_thickness_s_transmitted : slab_->log_thickness_s;
  const std::vector<TabulatedProfile>& nodes = transmitted ? slab_->transmitted : slab_->reflected;
  if (nodes.empty()) return relative_se(q, rho, alpha_prime, eta);
  const double t = std::log(thickness_s);
  const auto hi = std::size_t(std::lower_bound(x.begin(), x.end(), t) - x.begin());
  const std::size_t a = hi == 0 ? 0 : hi - 1, b = std::min(hi, x.size() - 1);
  return std::max(nodes[a].relative_se(q, rho, alpha_prime, eta),
                  nodes[b].relative_se(q, rho, alpha_prime, eta));
}

double TabulatedProfile::relative_se(TableQuantity q, double rho, double alpha_prime,
                                     double eta) const {
  const double u = std::sqrt(std::max(0.0, 1 - alpha_prime));
  const auto nearest = [](const std::vector<double>& x, double t) {
    const auto it = std::lower_bound(x.begin(), x.end(), t);
    if (it == x.begin()) return std::size_t(0);
    if (it == x.end()) return x.size() - 1;
    const std::size_t i = std::size_t(it - x.begin());
    return t - x[i - 1] < x[i] - t ? i - 1 : i;
  };
  const std::size_t s = nearest(eta_, eta), k = nearest(u_, u);
  const std::size_t j = nearest(x_, std::log(std::max(rho, 1e-300)));
  double worst = rel_se_[s][std::size_t(q)][k * std::size_t(J_) + j];
  // The interpolation leans on the neighbour in u as much: take the larger.
  if (k + 1 < u_.size())
    worst = std::max(worst, double(rel_se_[s][std::size_t(q)][(k + 1) * std::size_t(J_) + j]));
  if (rho > std::exp(x_.back())) worst = INFINITY;  // beyond the table: an extrapolation
  return worst;
}

std::shared_ptr<const TabulatedProfile> cached_tabulated_profile(const TransportTable& table,
                                                                 double g,
                                                                 std::optional<double> eta) {
  using Key = std::tuple<const TransportTable*, double, bool, double>;
  static std::mutex mutex;
  static std::map<Key, std::shared_ptr<const TabulatedProfile>> cache;
  const Key full_key{&table, g, false, 0.0};
  std::lock_guard lock(mutex);
  auto& full = cache[full_key];
  if (!full) full = std::make_shared<const TabulatedProfile>(table, g);
  if (!eta) return full;
  auto& fixed = cache[Key{&table, g, true, *eta}];
  if (!fixed) fixed = std::make_shared<const TabulatedProfile>(full->at_eta(*eta));
  return fixed;
}

double TabulatedProfile::total_relative_se(double alpha_prime, double eta) const {
  const double u = std::sqrt(std::max(0.0, 1 - alpha_prime));
  const std::size_t s = std::size_t(std::min_element(eta_.begin(), eta_.end(), [&](double a, double b) {
                                      return std::abs(a - eta) < std::abs(b - eta);
                                    }) - eta_.begin());
  const std::size_t k = std::min<std::size_t>(
      u_.size() - 1, std::size_t(std::upper_bound(u_.begin(), u_.end(), u) - u_.begin()));
  return std::max(total_rel_se_[s][k], total_rel_se_[s][k > 0 ? k - 1 : 0]);
}

std::string TabulatedProfile::to_string() const {
  std::ostringstream s;
  s << "TabulatedProfile{g=" << g_ << ", eta " << eta_.front() << ".." << eta_.back() << " ("
    << eta_.size() << " slices), " << u_.size() << " albedos, rho " << rho_min_ << ".."
    << rho_max_ << " (" << J_ << " bins), " << photons_ << " photons per slice}";
  return s.str();
}

}  // namespace lucent::materials
