// Finding or building the tables a fit needs beyond the shipped ones (fit_tables.h).
#include "fit_tables.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <iostream>
#include <map>
#include <sstream>

#include "lucent/acquire/tabulate.h"
#include "lucent/core/atomic_file.h"
#include "lucent/core/error.h"
#include "lucent/materials/oblique.h"
#include "lucent/materials/radial_slices.h"
#include "progress.h"

namespace lucent::cli {

namespace {

// The table `name` from the cache when it holds what `has` asks, else built from `o` now (progress
// on stderr unless quiet) and kept in the cache at once: a fit that fails later must not cost the
// next one this build. A cache that cannot be read or written is only a warning.
materials::TransportTable cached_or_built(
    const std::string& name, const acquire::TabulateOptions& o,
    const std::function<bool(const materials::TransportTable&)>& has, const std::string& what,
    const std::string& kind, bool quiet) {
  const std::filesystem::path dir = materials::oblique_cache_dir();
  const std::filesystem::path cached = dir.empty() ? std::filesystem::path() : dir / name;
  const materials::CacheEntry entry =
      cached.empty() ? materials::CacheEntry::kAbsent : materials::cache_entry(cached);
  if (entry == materials::CacheEntry::kOther)
    warn("lucent fit: warning: " + cached.string() +
         ": not a regular file, ignored (a table built now replaces it)");
  if (entry == materials::CacheEntry::kFile) {
    try {
      materials::TransportTable t = materials::read_transport_table(cached);
      if (has(t)) return t;
    } catch (const Error& e) {
      warn("lucent fit: warning: the cached " + kind + " table is unreadable, rebuilding it (" +
           std::string(e.what()) + ")");
    }
  }
  if (!quiet)
    std::cerr << "lucent fit: building the " << what << "; kept in "
              << (cached.empty() ? std::string("no cache") : cached.string()) << ")\n";
  ProgressLine line("lucent fit: " + kind + " table", "white-run photons", quiet);
  const auto progress = [&](std::uint64_t done, std::uint64_t total) { line.update(done, total); };
  materials::TransportTable t = acquire::tabulate_transport(o, progress);
  line.finish();
  if (!cached.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    try {
      if (ec) throw Error(dir.string() + ": " + ec.message());
      // Not through the run's output transaction: the cache's own write commits nothing of the
      // run's outputs (a batch interrupted after a build leaves none of its rows).
      CacheWriteScope now;
      materials::write_transport_table(t, cached);
    } catch (const Error& e) {
      warn("lucent fit: warning: the " + kind + " table is not kept (" + e.what() + ")");
    } catch (const std::exception& e) {
      warn("lucent fit: warning: the " + kind + " table is not kept (" + cached.string() + ": " +
           e.what() + ")");
    }
  }
  t.source = cached.empty() ? std::string("(built for this fit)") : cached.string();
  return t;
}

}  // namespace

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
  acquire::TabulateOptions o;
  o.eta = {*eta};
  o.g = {g};
  o.incidence_deg = {*incidence};
  o.grid = materials::default_oblique_grid();
  o.photons = photons;
  std::ostringstream what;
  what << "oblique transport table for eta " << *eta << ", g " << g << ", incidence " << *incidence
       << " degrees (" << photons << " photons";
  return cached_or_built(name.str(), o, has, what.str(), "oblique", quiet);
}

materials::TransportTableGrid radial_fit_grid() {
  materials::TransportTableGrid grid = materials::default_transport_grid();
  for (double u : {0.999, 0.9995, 0.9999}) grid.u.push_back(u);
  return grid;
}

const materials::TransportTable* radial_table_for(const std::vector<fit::ProfileData>& data,
                                                  const fit::FitOptions& options,
                                                  std::uint64_t photons, bool quiet) {
  // A table given with --table is the user's choice (its refusal of a g it lacks stands).
  if (options.table || options.fit_ior || options.model == fit::FitModel::kDipole ||
      options.model == fit::FitModel::kDirectionalDipole)
    return nullptr;
  for (const fit::ProfileData& d : data) {
    // Only radial profiles at normal incidence and view (what the tabulated model is for).
    if (d.samples_2d.has_value() || d.incidence_polar_deg > 0.5 ||
        (!d.exitance && d.view_deg > 0.5))
      return nullptr;
  }
  const std::optional<double> eta = options.ior ? options.ior : data.front().eta;
  if (!eta || *eta < 1.0 || *eta > 2.5) return nullptr;  // the fit says why
  const double g = options.g;
  // A slice at exactly this g, over an eta range that holds the data's (interpolating in eta is
  // harmless; in g it is not near black: coffee's green channel, g 0.896, was 8-9% off with the
  // shipped table's nodes 0.8 and 0.9 around it, and red, g 0.907, 0.2-0.8% off with its own).
  const auto has = [&](const materials::TransportTable& t) {
    if (t.partial || t.grid.phi_bins != 1) return false;
    double eta_min = INFINITY, eta_max = -INFINITY;
    for (const materials::TransportTableSlice& s : t.slices) {
      if (std::abs(s.g - g) > 1e-9) continue;
      eta_min = std::min(eta_min, s.eta), eta_max = std::max(eta_max, s.eta);
    }
    return *eta >= eta_min - 1e-9 && *eta <= eta_max + 1e-9;
  };
  // A shipped table that cannot be read is the fit's to report.
  try {
    if (has(materials::default_transport_table())) return nullptr;
  } catch (const Error&) {
    return nullptr;
  }
  acquire::TabulateOptions o;
  o.eta = {*eta};
  o.g = {g};
  o.grid = radial_fit_grid();
  o.photons = photons;
  // The white run (alpha' >= 0.4) costs 1 / (1 - g) collisions per transport length: scaled so
  // that it costs what 150,000 photons cost at g = 0.9 per million (about a minute here); the
  // near-black nodes, which the media of such g need most, are direct runs of the full count.
  o.white_photons = std::clamp(std::uint64_t(double(photons) * 1.5 * (1 - g)),
                               std::uint64_t(o.groups) * 64, photons);
  // Kept for the process (a batch's rows of one (eta, g) share it; the prepared profiles are keyed
  // by the table's address, which must not be reused by another table).
  // (Batch rows run one after another: no lock.)
  static std::map<std::string, const materials::TransportTable*> kept;
  const std::string name = materials::radial_slice_file_name(*eta, g, photons);
  if (const auto it = kept.find(name); it != kept.end()) return it->second;
  std::ostringstream what;
  what << "radial transport table for eta " << *eta << ", g " << g << " (" << photons
       << " photons per albedo node, " << o.white_photons << " in the white run";
  const materials::TransportTable* t =
      &materials::keep_transport_table(cached_or_built(name, o, has, what.str(), "radial", quiet));
  kept[name] = t;
  return t;
}

const std::vector<double>& slab_thickness_nodes() {
  static const std::vector<double> nodes = {0.25, 0.5, 1, 2, 4, 8, 16, 32, 64};
  return nodes;
}

std::shared_ptr<const materials::SlabNodes> slab_nodes_for(const std::vector<fit::ProfileData>& data,
                                                          const fit::FitOptions& options,
                                                          std::uint64_t photons, bool quiet) {
  bool slab = false, far = false;
  for (const fit::ProfileData& d : data) {
    slab = slab || options.thickness_mm || options.fit_thickness || d.thickness_mm;
    far = far || d.transmitted;
  }
  if (!slab || options.fit_ior || options.model == fit::FitModel::kDipole ||
      options.model == fit::FitModel::kDirectionalDipole)
    return nullptr;
  const std::optional<double> eta = options.ior ? options.ior : data.front().eta;
  if (!eta || *eta < 1.0 || *eta > 2.5) return nullptr;  // the fit says why
  const double g = options.g;
  auto nodes = std::make_shared<materials::SlabNodes>();
  std::ostringstream source;
  source.precision(12);
  source << "slab tables at eta " << *eta << ", g " << g << ", " << photons << " photons each";
  nodes->source = source.str();
  // Kept for the process (a batch's rows of one (eta, g) share them).
  static std::map<std::string, std::shared_ptr<const materials::TabulatedProfile>> kept;
  for (const bool transmitted : {false, true}) {
    if (transmitted && !far) break;
    for (const double t : slab_thickness_nodes()) {
      std::ostringstream name;
      name.precision(12);
      name << "slab2-eta" << *eta << "-g" << g << "-t" << t << "-"
           << (transmitted ? "transmitted" : "reflected") << "-n" << photons << ".lut";
      std::shared_ptr<const materials::TabulatedProfile>& profile = kept[name.str()];
      if (!profile) {
        acquire::TabulateOptions o;
        o.eta = {*eta};
        o.g = {g};
        o.photons = photons;
        o.white_photons = std::clamp(std::uint64_t(double(photons) * 1.5 * (1 - g)),
                                     std::uint64_t(o.groups) * 64, photons);
        // Near-black nodes down to alpha' 2e-4, as for a radial slice (high-g media need them).
        o.grid = radial_fit_grid();
        o.thickness_s = t;
        o.transmitted = transmitted;
        const auto has = [&](const materials::TransportTable& table) {
          return !table.partial && table.slab() && table.slab_thickness_s == t &&
                 table.transmitted == transmitted && table.slices.size() == 1 &&
                 std::abs(table.slices[0].eta - *eta) < 1e-12 &&
                 std::abs(table.slices[0].g - g) < 1e-12;
        };
        std::ostringstream what;
        what << "slab table for eta " << *eta << ", g " << g << ", d sigma_s' " << t << ", "
             << (transmitted ? "far" : "lit") << " side (" << photons << " photons";
        const materials::TransportTable table =
            cached_or_built(name.str(), o, has, what.str(), "slab", quiet);
        profile = std::make_shared<const materials::TabulatedProfile>(
            materials::TabulatedProfile::slab_node(table, g));
      }
      (transmitted ? nodes->transmitted : nodes->reflected).push_back(*profile);
      (transmitted ? nodes->log_thickness_s_transmitted : nodes->log_thickness_s)
          .push_back(std::log(t));
    }
  }
  return nodes;
}

}  // namespace lucent::cli
