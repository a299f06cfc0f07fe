// Radial slices kept in the cache (radial_slices.h).
#include "lucent/materials/radial_slices.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <filesystem>
#include <map>
#include <mutex>
#include <sstream>
#include <utility>
#include <vector>

#include "lucent/core/error.h"
#include "lucent/materials/oblique.h"

namespace lucent::materials {
namespace {

std::string file_prefix(double eta, double g) {
  std::ostringstream name;
  // "radial1": the first layout of these slices (the radial fit grid, near-black nodes included).
  // 12 digits: values that print alike are within the 1e-9 a slice is matched to (0.917 -> 0.917).
  name.precision(12);
  name << "radial1-eta" << eta << "-g" << g << "-n";
  return name.str();
}

std::mutex& kept_mutex() {
  static std::mutex m;
  return m;
}
std::deque<TransportTable>& kept_tables() {  // a deque: elements never move
  static std::deque<TransportTable> tables;
  return tables;
}

}  // namespace

std::string radial_slice_file_name(double eta, double g, std::uint64_t photons) {
  return file_prefix(eta, g) + std::to_string(photons) + ".lut";
}

const TransportTable& keep_transport_table(TransportTable table) {
  std::lock_guard lock(kept_mutex());
  return kept_tables().emplace_back(std::move(table));
}

const TransportTable* cached_radial_slice(double eta, double g) {
  static std::mutex mutex;
  static std::map<std::pair<double, double>, const TransportTable*> found;
  std::lock_guard lock(mutex);
  const auto key = std::make_pair(eta, g);
  if (const auto it = found.find(key); it != found.end()) return it->second;
  // The slice of most photons that reads and holds (eta, g); anything unreadable is passed over.
  const TransportTable* best = nullptr;
  const std::filesystem::path dir = oblique_cache_dir();
  std::vector<std::pair<std::uint64_t, std::filesystem::path>> candidates;
  try {
    std::error_code ec;
    if (!dir.empty() && std::filesystem::is_directory(dir, ec)) {
      const std::string prefix = file_prefix(eta, g);
      for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
        const std::string name = entry.path().filename().string();
        if (name.rfind(prefix, 0) != 0 || name.size() <= prefix.size() + 4 ||
            name.substr(name.size() - 4) != ".lut")
          continue;
        const std::string digits = name.substr(prefix.size(), name.size() - prefix.size() - 4);
        if (digits.empty() || digits.size() > 18 ||
            digits.find_first_not_of("0123456789") != std::string::npos)
          continue;
        candidates.emplace_back(std::stoull(digits), entry.path());
      }
    }
  } catch (const std::exception&) {
    // A cache folder that cannot be listed: as if empty.
  }
  std::sort(candidates.begin(), candidates.end(),
            [](const auto& a, const auto& b) { return a.first > b.first; });
  for (const auto& [photons, path] : candidates) {
    // Regular files only: a FIFO named like a slice would block the run (oblique.h, cache_entry).
    if (cache_entry(path) != CacheEntry::kFile) continue;
    try {
      TransportTable t = read_transport_table(path);
      bool slice = false;
      for (const TransportTableSlice& s : t.slices)
        slice = slice || (std::abs(s.g - g) < 1e-9 && std::abs(s.eta - eta) < 1e-9);
      if (t.partial || t.grid.phi_bins != 1 || !slice) continue;
      best = &keep_transport_table(std::move(t));
      break;
    } catch (const Error&) {
      // Unreadable: the next one (the next fit that needs it rebuilds it).
    }
  }
  found[key] = best;
  return best;
}

std::shared_ptr<const TabulatedProfile> radial_profile_for(double g, double eta) {
  const TransportTable* slice = cached_radial_slice(eta, g);
  const TransportTable& table = slice ? *slice : default_transport_table();
  std::shared_ptr<const TabulatedProfile> full;
  try {
    full = cached_tabulated_profile(table, g);
  } catch (const Error& e) {
    if (std::string(e.what()).rfind("--g", 0) != 0) throw;  // not a g the table lacks
    std::ostringstream m;
    m << "g: " << g << " (the material's) has no slice in the transport table at eta " << eta
      << " (" << e.what() << "); a lucent fit with --g " << g
      << " of data at that eta builds one and keeps it in the cache ($LUCENT_CACHE_DIR or "
         "~/.cache/lucent)";
    throw Error(m.str());
  }
  if (eta < full->eta_min() - 1e-12 || eta > full->eta_max() + 1e-12) {
    std::ostringstream m;
    m << "ior: " << eta << " is outside the transport table's eta range " << full->eta_min() << ".."
      << full->eta_max();
    throw Error(m.str());
  }
  return cached_tabulated_profile(table, g, eta);
}

}  // namespace lucent::materials
