// The tabulated model's preparation of a table (tabulated.h).
#include "lucent/materials/tabulated.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>

#include "lucent/materials/error.h"

namespace lucent::materials {
namespace {

// Annulus average -> point value at the bin's log centre. With x = ln(rho), f = ln(value) and the
// area element rho^2 dx, the average over a bin of width h is, to second order,
//   ln(avg) = f + ((f' + 2)^2 + f'' - 4) h^2 / 24,
// so f is ln(avg) less that term, with f', f'' from central differences of ln(avg) (the term is
// 1e-3 of f in the steep near field: small, but it is bias, and removing it is free).
void to_point_values(std::vector<double>& f, int J, double h) {
  std::vector<double> out = f;
  for (int j = 1; j + 1 < J; ++j) {
    const double d1 = (f[std::size_t(j + 1)] - f[std::size_t(j - 1)]) / (2 * h);
    const double d2 = (f[std::size_t(j + 1)] - 2 * f[std::size_t(j)] + f[std::size_t(j - 1)]) / (h * h);
    out[std::size_t(j)] = f[std::size_t(j)] - ((d1 + 2) * (d1 + 2) + d2 - 4) * h * h / 24;
  }
  f = out;
}

}  // namespace

TabulatedProfile::TabulatedProfile(const TransportTable& table, double g) : g_(g) {
  if (table.partial) throw Error(table.source + ": a partial table (merge the shards first)");
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
  const double h = std::log(10.0) / table.grid.rho_per_decade;
  for (int j = 0; j < J_; ++j) x_.push_back(std::log(table.grid.rho_centre(j)));

  // g weights (double): a node, or the Hermite interpolant between nodes.
  const NodeWeights<double> wg = hermite_weights(g_nodes, g, false);
  const std::size_t K = u_.size(), n = K * std::size_t(J_);
  photons_ = ~std::uint64_t(0);
  for (std::size_t e = 0; e < eta_.size(); ++e) {
    std::array<std::vector<double>, kTableQuantities> f;
    std::array<std::vector<float>, kTableQuantities> se;
    std::vector<double> lt(K, 0.0);
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
            row[std::size_t(j)] = std::log(double(s.value[std::size_t(q)][k * std::size_t(J_) + std::size_t(j)]) / a);
          to_point_values(row, J_, h);
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
      }
    }
    f_.push_back(std::move(f));
    rel_se_.push_back(std::move(se));
    log_total_.push_back(std::move(lt));
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
  return p;
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

std::string TabulatedProfile::to_string() const {
  std::ostringstream s;
  s << "TabulatedProfile{g=" << g_ << ", eta " << eta_.front() << ".." << eta_.back() << " ("
    << eta_.size() << " slices), " << u_.size() << " albedos, rho " << rho_min_ << ".."
    << rho_max_ << " (" << J_ << " bins), " << photons_ << " photons per slice}";
  return s.str();
}

}  // namespace lucent::materials
