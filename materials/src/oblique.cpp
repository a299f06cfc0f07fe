// The oblique tabulated model's preparation of a table slice (oblique.h).
#include "lucent/materials/oblique.h"

#include <algorithm>
#include <cstdlib>
#include <random>
#include <sstream>

#include "lucent/core/error.h"

namespace lucent::materials {
namespace {

constexpr double kSliceMatch = 1e-6;

const TransportTableSlice* find_slice(const TransportTable& table, double eta, double g,
                                      double incidence_deg) {
  for (const TransportTableSlice& s : table.slices)
    if (std::abs(s.eta - eta) < kSliceMatch && std::abs(s.g - g) < kSliceMatch &&
        std::abs(s.incidence_deg - incidence_deg) < kSliceMatch)
      return &s;
  return nullptr;
}

// Wedge averages -> point values at the wedge centres, per radius: the average of a smooth f over
// a wedge of width h is f + h^2 f'' / 24 to second order, so p = avg - h^2 p'' / 24 by fixed-point
// rounds, p'' from central differences continued evenly across 0 and pi. (In log value: the
// profile is ~ e^(a cos phi) in phi, smooth; at 15-degree wedges the correction is ~0.2%.)
void wedges_to_points(std::vector<double>& f, int P, int J) {
  if (P < 3) return;
  const std::vector<double> avg = f;
  const auto at = [&](const std::vector<double>& v, int p, int j) {
    if (p < 0) p = -p - 1;
    if (p >= P) p = 2 * P - 1 - p;
    return v[std::size_t(p) * std::size_t(J) + std::size_t(j)];
  };
  for (int round = 0; round < 3; ++round) {
    std::vector<double> next = f;
    for (int p = 0; p < P; ++p)
      for (int j = 0; j < J; ++j) {
        const double d2 = at(f, p - 1, j) - 2 * at(f, p, j) + at(f, p + 1, j);
        next[std::size_t(p) * std::size_t(J) + std::size_t(j)] =
            avg[std::size_t(p) * std::size_t(J) + std::size_t(j)] - d2 / 24;
      }
    f = next;
  }
}

}  // namespace

bool ObliqueProfile::has_slice(const TransportTable& table, double eta, double g,
                               double incidence_deg) {
  return !table.partial && table.grid.phi_bins > 1 && table.single_scattering_line_excluded &&
         find_slice(table, eta, g, incidence_deg);
}

ObliqueProfile::ObliqueProfile(const TransportTable& table, double eta, double g,
                               double incidence_deg) {
  if (table.partial) throw Error(table.source + ": a partial table (merge the shards first)");
  if (table.grid.phi_bins < 2)
    throw Error(table.source + ": not an oblique table (no azimuth wedges; build one with "
                "lucent tabulate --incidence-deg)");
  if (!table.single_scattering_line_excluded)
    throw Error(table.source + ": an oblique table from an older lucent (its radiance holds the "
                "beam's single-scattering line): rebuild it with lucent tabulate --incidence-deg");
  const TransportTableSlice* s = find_slice(table, eta, g, incidence_deg);
  if (!s) {
    std::ostringstream m;
    m << table.source << ": no slice at eta " << eta << ", g " << g << ", incidence "
      << incidence_deg << " degrees (build it with lucent tabulate --eta " << eta << " --g " << g
      << " --incidence-deg " << incidence_deg << ")";
    throw Error(m.str());
  }
  eta_ = s->eta, g_ = s->g, incidence_deg_ = s->incidence_deg;
  P_ = table.grid.phi_bins;
  J_ = table.grid.rho_bins();
  u_ = table.grid.u;
  photons_ = s->photons;
  for (int j = 0; j < J_; ++j) x_.push_back(std::log(table.grid.rho_centre(j)));
  const std::size_t K = u_.size(), block = std::size_t(P_) * std::size_t(J_);
  for (int q = 0; q < kTableQuantities; ++q) {
    std::vector<double>& f = f_[std::size_t(q)];
    std::vector<float>& se = rel_se_[std::size_t(q)];
    f.assign(K * block, 0.0);
    se.assign(K * block, 0.0f);
    for (std::size_t k = 0; k < K; ++k) {
      const double a = 1 - u_[k] * u_[k];
      std::vector<double> node(block);
      for (int p = 0; p < P_; ++p) {
        std::vector<double> row(static_cast<std::size_t>(J_));
        for (int j = 0; j < J_; ++j) {
          const std::size_t i = (k * std::size_t(P_) + std::size_t(p)) * std::size_t(J_) + std::size_t(j);
          row[std::size_t(j)] = std::log(std::max(double(s->value[std::size_t(q)][i]), 1e-37) / a);
          se[i] = float(decode_relative_se(s->se_code[std::size_t(q)][i]));
        }
        detail::to_point_values(row, x_, table.grid);
        std::copy(row.begin(), row.end(), node.begin() + long(std::size_t(p) * std::size_t(J_)));
      }
      wedges_to_points(node, P_, J_);
      std::copy(node.begin(), node.end(), f.begin() + long(k * block));
    }
  }
}

ObliqueProfile ObliqueProfile::perturbed(std::uint64_t seed) const {
  ObliqueProfile p = *this;
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (int q = 0; q < kTableQuantities; ++q) {
    std::vector<double>& f = p.f_[std::size_t(q)];
    const std::vector<float>& se = p.rel_se_[std::size_t(q)];
    for (std::size_t i = 0; i < f.size(); ++i) {
      const double draw = normal(rng);
      if (std::isfinite(se[i])) f[i] += draw * std::min(double(se[i]), 1.0);
    }
  }
  return p;
}

double ObliqueProfile::relative_se(TableQuantity q, double rho, double phi,
                                   double alpha_prime) const {
  if (!(rho > 0) || std::log(rho) > x_.back()) return INFINITY;
  const double u = std::sqrt(std::max(0.0, 1 - alpha_prime));
  const std::size_t k0 = std::size_t(
      std::max<long>(0, long(std::upper_bound(u_.begin(), u_.end(), u) - u_.begin()) - 1));
  const std::size_t k1 = std::min(k0 + 1, u_.size() - 1);
  const double step = x_.size() > 1 ? x_[1] - x_[0] : 1;
  const std::size_t j = std::size_t(std::clamp(
      long(std::lround((std::log(rho) - x_.front()) / step)), 0L, long(J_) - 1));
  const std::size_t p = std::size_t(std::clamp(int(phi * P_ / std::numbers::pi), 0, P_ - 1));
  const auto at = [&](std::size_t k) {
    return double(rel_se_[std::size_t(q)][(k * std::size_t(P_) + p) * std::size_t(J_) + j]);
  };
  return std::max(at(k0), at(k1));
}

std::string ObliqueProfile::to_string() const {
  std::ostringstream s;
  s << "ObliqueProfile{eta=" << eta_ << ", g=" << g_ << ", incidence " << incidence_deg_
    << " deg, " << u_.size() << " albedos, " << P_ << " azimuths, " << J_ << " radii, "
    << photons_ << " photons}";
  return s.str();
}

std::filesystem::path oblique_cache_dir() {
  if (const char* d = std::getenv("LUCENT_CACHE_DIR"); d && *d) return d;
  if (const char* d = std::getenv("XDG_CACHE_HOME"); d && *d)
    return std::filesystem::path(d) / "lucent";
  if (const char* d = std::getenv("HOME"); d && *d)
    return std::filesystem::path(d) / ".cache" / "lucent";
  return {};
}

CacheEntry cache_entry(const std::filesystem::path& path) {
  std::error_code ec;
  const std::filesystem::file_status st = std::filesystem::status(path, ec);
  if (st.type() == std::filesystem::file_type::not_found) return CacheEntry::kAbsent;
  if (ec) return CacheEntry::kOther;  // a loop, a folder that cannot be searched
  return st.type() == std::filesystem::file_type::regular ? CacheEntry::kFile : CacheEntry::kOther;
}

}  // namespace lucent::materials
