// The technique registry (technique.h): the only place a technique's name is compared.
#include "lucent/render/technique.h"

#include <algorithm>
#include <cstdio>

#include "lucent/core/error.h"
#include "lucent/render/fur_renderer.h"
#include "lucent/render/hierarchical_renderer.h"

namespace lucent::render {

using materials::DiffusionModel;

namespace {
template <class Renderer>
std::unique_ptr<Technique> make() {
  return std::make_unique<Renderer>();
}
}  // namespace

bool TechniqueInfo::supports(DiffusionModel model) const {
  return std::find(models.begin(), models.end(), model) != models.end();
}

const std::vector<TechniqueInfo>& techniques() {
  const std::vector<DiffusionModel> all = {DiffusionModel::kTabulated,
                                           DiffusionModel::kDirectionalDipole,
                                           DiffusionModel::kDipole};
  static const std::vector<TechniqueInfo> table = {
      {TechniqueId::kMaps, "maps", "radiance maps", "radiance maps",
       "maps (real-time radiance maps, OpenGL)", true, all, "", true, true, true,
       &make<RadianceMapRenderer>, true},
      {TechniqueId::kSh, "sh", "SH fast translucency", "SH fast",
       "sh (spherical-harmonics fast translucency, OpenGL, Banterle & Chalmers: not physically "
       "based)",
       false, all, "", true, false, false, &make<ShRenderer>},
      {TechniqueId::kHierarchical,
       "hierarchical",
       "hierarchical boundary elements",
       "hierarchical",
       "hierarchical (boundary elements on a face-cluster hierarchy, Mertens et al.: the standard "
       "dipole, solved on the CPU, shaded per vertex on the GPU)",
       true,
       {DiffusionModel::kDipole},
       "integrates the standard dipole (Mertens et al.)",
       true,
       true,
       false,
       &make<HierarchicalRenderer>,
       true},
      {TechniqueId::kFur, "fur", "fur shells with SH transfer", "fur",
       "fur (Klotzli & Olano: shells with SH transfer; --mesh tile is the seed's tile, other "
       "meshes get a "
       "coat of shells over the maps' skin: an extension)",
       true, all, "", true, true, false, &make<FurRenderer>},
      {TechniqueId::kReference, "reference", "CPU reference", "CPU reference",
       "reference (CPU, slow, exact up to sampling noise)", true, all, "", false, true, false,
       nullptr, true},
      {TechniqueId::kPathtrace, "pathtrace", "path-traced truth", "path tracer",
       "pathtrace (CPU volumetric path tracing of the medium behind its smooth boundary: the "
       "truth the others are held to; no diffusion model, --model is ignored)",
       true, all, "traces the medium itself", false, false, false, nullptr, true},
  };
  return table;
}

const TechniqueInfo& technique_info(TechniqueId id) {
  for (const TechniqueInfo& t : techniques())
    if (t.id == id) return t;
  throw std::logic_error("technique_info: a technique missing from the registry");
}

const TechniqueInfo* find_technique(std::string_view name) {
  for (const TechniqueInfo& t : techniques())
    if (t.name == name) return &t;
  return nullptr;
}

std::string technique_names(const std::function<bool(const TechniqueInfo&)>& which) {
  std::vector<std::string> names;
  for (const TechniqueInfo& t : techniques())
    if (!which || which(t)) names.push_back(t.name);
  std::string list;
  for (std::size_t i = 0; i < names.size(); ++i)
    list += (i == 0 ? "" : i + 1 == names.size() ? " or " : ", ") + names[i];
  return list;
}

std::unique_ptr<Technique> make_technique(TechniqueId id) {
  const TechniqueInfo& info = technique_info(id);
  if (info.make == nullptr) {
    throw std::logic_error("make_technique: " + info.name + " renders stills only");
  }
  return info.make();
}

TechniqueId parse_technique(std::string_view name, const std::string& option) {
  if (const TechniqueInfo* t = find_technique(name)) return t->id;
  throw Error(option + ": expected " + technique_names() + ", got '" + std::string(name) + "'");
}

ImageRgb render_still(TechniqueId id, const Scene& scene, const TechniqueOptions& options,
                      RenderStats* stats) {
  switch (id) {
    case TechniqueId::kReference: {
      ReferenceImage result = render_reference(scene, options.settings.model, options.reference);
      if (stats) *stats = std::move(result.stats);
      return std::move(result.image);
    }
    case TechniqueId::kPathtrace: {
      PathTraceImage result = render_pathtrace(scene, options.pathtrace);
      if (stats) *stats = std::move(result.stats);
      return std::move(result.image);
    }
    case TechniqueId::kSh: return render_sh(scene, options.sh, stats);
    case TechniqueId::kHierarchical:
      return render_hierarchical(scene, options.hierarchical, stats);
    case TechniqueId::kFur: return render_fur(scene, options.fur, stats, options.settings);
    case TechniqueId::kMaps:
      return render_radiance_maps(scene, options.settings, options.maps, stats, nullptr);
  }
  throw std::logic_error("render_still: a technique without a renderer");
}

std::string FrameStats::to_string() const {
  std::string text = "frames " + std::to_string(frames);
  for (std::size_t i = 0; i < pass_ms.size(); ++i) {
    char ms[32];
    std::snprintf(ms, sizeof ms, "%.2f", pass_ms[i].second);
    text += (i == 0 ? "; " : ", ") + pass_ms[i].first + " " + ms + " ms";
  }
  for (const std::string& note : notes) text += "; " + note;
  return text;
}

std::string settings_text(TechniqueId id, const TechniqueOptions& options) {
  switch (id) {
    case TechniqueId::kMaps:
      return options.settings.to_string() + " " + options.maps.to_string();
    case TechniqueId::kSh: return options.sh.to_string();
    case TechniqueId::kHierarchical:
      return options.hierarchical.to_string();
    case TechniqueId::kFur:
      return options.fur.to_string();
    case TechniqueId::kReference:
      return options.reference.to_string();
    case TechniqueId::kPathtrace:
      return options.pathtrace.to_string();
  }
  return "";
}

}  // namespace lucent::render
