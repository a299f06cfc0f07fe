// Finding or building the oblique slice of a fit (oblique_table.h).
#include "oblique_table.h"

#include <cmath>
#include <filesystem>
#include <iostream>
#include <sstream>

#include "lucent/acquire/tabulate.h"
#include "lucent/materials/atomic_file.h"
#include "lucent/materials/error.h"
#include "lucent/materials/oblique.h"
#include "progress.h"

namespace lucent::cli {

std::optional<materials::TransportTable> oblique_table_for(
    const std::vector<fit::ProfileData>& data, const fit::FitOptions& options,
    const std::string& given, std::uint64_t photons, bool quiet) {
  if (given == "none" || options.fit_ior || options.model == fit::FitModel::kDipole ||
      options.model == fit::FitModel::kDirectionalDipole)
    return std::nullopt;
  std::optional<double> incidence;
  for (const fit::ProfileData& d : data) {
    if (!(d.samples_2d.has_value() && d.incidence_polar_deg > 0)) continue;
    if (incidence && std::abs(*incidence - d.incidence_polar_deg) > 1e-6)
      return std::nullopt;  // several incidences: the fit falls back (and says so)
    incidence = d.incidence_polar_deg;
  }
  if (!incidence) return std::nullopt;
  const std::optional<double> eta = options.ior ? options.ior : data.front().eta;
  if (!eta) return std::nullopt;
  const double g = options.g;
  const auto has = [&](const materials::TransportTable& t) {
    return materials::ObliqueProfile::has_slice(t, *eta, g, *incidence);
  };
  if (!given.empty()) {
    materials::TransportTable t = materials::read_transport_table(given);
    if (!has(t)) materials::ObliqueProfile(t, *eta, g, *incidence);  // throws, naming the slice
    return t;
  }
  if (const auto shipped = materials::default_oblique_table_path();
      std::filesystem::exists(shipped)) {
    materials::TransportTable t = materials::read_transport_table(shipped);
    if (has(t)) return t;
  }
  std::ostringstream name;
  // "2": the table format whose radiance leaves the single-scattering line out.
  name << "oblique2-eta" << *eta << "-g" << g << "-inc" << *incidence << "-n" << photons << ".lut";
  const std::filesystem::path dir = materials::oblique_cache_dir();
  const std::filesystem::path cached = dir.empty() ? std::filesystem::path() : dir / name.str();
  if (!cached.empty() && std::filesystem::exists(cached)) {
    try {
      materials::TransportTable t = materials::read_transport_table(cached);
      if (has(t)) return t;
    } catch (const Error& e) {
      warn("lucent fit: warning: the cached oblique table is unreadable, rebuilding it (" +
           std::string(e.what()) + ")");
    }
  }
  acquire::TabulateOptions o;
  o.eta = {*eta};
  o.g = {g};
  o.incidence_deg = {*incidence};
  o.grid = materials::default_oblique_grid();
  o.photons = photons;
  if (!quiet)
    std::cerr << "lucent fit: building the oblique transport table for eta " << *eta << ", g "
              << g << ", incidence " << *incidence << " degrees (" << photons
              << " photons; kept in " << (cached.empty() ? std::string("no cache") : cached.string())
              << ")\n";
  ProgressLine line("lucent fit: oblique table", "white-run photons", quiet);
  const auto progress = [&](std::uint64_t done, std::uint64_t total) { line.update(done, total); };
  materials::TransportTable t = acquire::tabulate_transport(o, progress);
  line.finish();
  if (!cached.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    // Kept at once (the fit's own outputs are still to come): a fit that fails later must not
    // cost the next one this build. A cache that cannot be written is only a warning.
    try {
      if (ec) throw Error(dir.string() + ": " + ec.message());
      materials::write_transport_table(t, cached);
      commit_pending_outputs();
    } catch (const Error& e) {
      warn(std::string("lucent fit: warning: the oblique table is not kept (") + e.what() + ")");
    }
  }
  t.source = cached.empty() ? std::string("(built for this fit)") : cached.string();
  return t;
}

}  // namespace lucent::cli
