// The viewer's panel (Dear ImGui): material, model and technique, the radiance maps' knobs, the
// scene, progress and the difference against the reference (viewer_impl.h).
#include "area_light.h"
#include "viewer_impl.h"

namespace lucent::render::viewer_detail {
namespace {

bool slider_done() { return ImGui::IsItemDeactivatedAfterEdit(); }

void section(const char* title) {
  ImGui::Separator();
  ImGui::TextDisabled("%s", title);
}

}  // namespace

void Viewer::draw_ui() {
  // At most 40% of the window's width and its height less a margin (it scrolls beyond); the
  // sections fold, only the material open at first, so a small window keeps most of its image.
  const float scale = ImGui::GetIO().FontGlobalScale;
  ImGui::SetNextWindowPos(ImVec2(6, 6), ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowSizeConstraints(ImVec2(0, 0),
                                      ImVec2(0.4f * float(width_), float(height_) - 12.0f));
  ImGui::SetNextWindowBgAlpha(0.75f);
  // A small window starts with the panel folded to its title bar (click it, or H, to open).
  ImGui::SetNextWindowCollapsed(height_ < 480, ImGuiCond_FirstUseEver);
  ImGui::Begin("lucent", nullptr, ImGuiWindowFlags_AlwaysAutoResize);
  ImGui::PushItemWidth(120 * scale);

  draw_choices();
  draw_maps_knobs();
  draw_scene_controls();
  draw_progress();
  if (!message_.empty()) ImGui::TextWrapped("%s", message_.c_str());
  ImGui::TextDisabled("drag: orbit  right drag: light  wheel: zoom");
  ImGui::TextDisabled("S screenshot  R restart  H hide  D difference  Esc quit");
  ImGui::PopItemWidth();
  ImGui::End();
}

// Material (the library or a file), technique and model, and the material's own controls.
void Viewer::draw_choices() {
  // Material: the library, or a file (reloaded when it changes on disk).
  if (ImGui::BeginCombo("material", scene_.material.name.c_str())) {
    for (const std::string& name : materials::library_material_names()) {
      if (ImGui::Selectable(name.c_str(), name == material_source_)) load_material(name);
    }
    ImGui::EndCombo();
  }
  ImGui::InputText("file", material_path_.data(), material_path_.size());
  ImGui::SameLine();
  if (ImGui::Button("load")) load_material(material_path_.data());

  // Technique and model.
  // Every technique of the registry; fur only on its tile (its shells over other meshes are
  // `lucent render`'s).
  int technique = int(technique_);
  bool first = true;
  for (const TechniqueInfo& t : techniques()) {
    if (t.id == TechniqueId::kFur && scene_.mesh.name != "tile") continue;
    if (!first) ImGui::SameLine();
    first = false;
    if (ImGui::RadioButton(t.panel_label.c_str(), &technique, int(t.id))) set_technique(t.id);
  }
  if (technique_ == TechniqueId::kFur) ImGui::Checkbox("rotating lobe light (L)", &fur_lobe_);
  int model = settings_.model == DiffusionModel::kDirectionalDipole ? 0
              : settings_.model == DiffusionModel::kDipole          ? 1
                                                                    : 2;
  if (ImGui::RadioButton("ddipole", &model, 0) || (ImGui::SameLine(), false) ||
      ImGui::RadioButton("dipole", &model, 1) || (ImGui::SameLine(), false) ||
      ImGui::RadioButton("tabulated", &model, 2)) {
    settings_.model = pending_.model = model == 0   ? DiffusionModel::kDirectionalDipole
                                       : model == 1 ? DiffusionModel::kDipole
                                                    : DiffusionModel::kTabulated;
    model_from_material_ = false;
    rebuild_maps();
    scene_changed();
  }
  if (ImGui::CollapsingHeader("material", ImGuiTreeNodeFlags_DefaultOpen)) {
    draw_material_controls();
  }
}

// The speed/accuracy knobs: applied when a slider is let go (they rebuild the maps).
void Viewer::draw_maps_knobs() {
  if (ImGui::CollapsingHeader("radiance maps")) {
  bool apply = false;
  int disc = pending_.disc_selection == DiscSelection::kStrata ? 0 : 1;
  if (ImGui::RadioButton("strata", &disc, 0) || ImGui::RadioButton("N nearest (seed)", &disc, 1)) {
    pending_.disc_selection = disc == 0 ? DiscSelection::kStrata : DiscSelection::kNearest;
    apply = true;
  }
  ImGui::SliderInt("N samples", &pending_.samples, 1, std::min(pending_.disc_points, 512));
  apply |= slider_done();
  ImGui::SliderInt("M disc points", &pending_.disc_points, 1, 4000);
  apply |= slider_done();
  float q = float(pending_.q);
  if (ImGui::SliderFloat("q", &q, 0.1f, 10.0f, "%.2f", ImGuiSliderFlags_Logarithmic)) pending_.q = q;
  apply |= slider_done();
  ImGui::SliderInt("K directions", &pending_.directions, 1, 64);
  apply |= slider_done();
  ImGui::SliderInt("T frames", &pending_.frames, 1, 1000);
  apply |= slider_done();
  for (auto [label, value] : {std::pair{"W_s radiance map", &pending_.radiance_map_size},
                              std::pair{"W_l light map", &pending_.light_map_size}}) {
    int index = int(std::find(kMapSizes.begin(), kMapSizes.end(), *value) - kMapSizes.begin());
    index = std::min(index, int(kMapSizes.size()) - 1);
    if (ImGui::SliderInt(label, &index, 0, int(kMapSizes.size()) - 1,
                         std::to_string(kMapSizes[std::size_t(index)]).c_str())) {
      *value = kMapSizes[std::size_t(index)];
    }
    apply |= slider_done();
  }
  if (apply) {
    pending_.samples = std::min(pending_.samples, pending_.disc_points);
    try {
      pending_.validate();
      settings_ = pending_;
      rebuild_maps();
    } catch (const Error& e) {
      message_ = e.what();
      pending_ = settings_;
    }
  }

  }
}

// Exposure, object size, the deformer and the dragged light.
void Viewer::draw_scene_controls() {
  if (ImGui::CollapsingHeader("scene")) {
  ImGui::SliderFloat("exposure", &settings_.exposure, 0.01f, 100.0f, "%.3g",
                     ImGuiSliderFlags_Logarithmic);
  pending_.exposure = settings_.exposure;
  float size = float(object_size_mm_);
  ImGui::SliderFloat("object size mm", &size, 1.0f, 2000.0f, "%.4g", ImGuiSliderFlags_Logarithmic);
  if (slider_done()) set_object_size(size);
  float deform = deform_amplitude_;
  ImGui::SliderFloat("deform", &deform, 0.0f, 0.2f, "%.3f");
  if (slider_done()) set_deform(deform);
  if (scene_.lights.size() > 1) {
    ImGui::SliderInt("dragged light", &selected_light_, 0, int(scene_.lights.size()) - 1);
  }
  if (scene_.lights[std::size_t(selected_light_)].type == LightType::kArea) {
    const Light& rect = scene_.lights[std::size_t(selected_light_)];
    ImGui::Text("rect %.0f mm^2 at %.0f mm", area_light_area(rect),
                double(area_light_centroid(rect).norm()));
    if (ImGui::Button("smaller [")) scale_selected_light(1 / 1.25f);
    ImGui::SameLine();
    if (ImGui::Button("larger ]")) scale_selected_light(1.25f);
  }
  if (on_cpu() && deformer_) ImGui::TextUnformatted("(the deformer pauses for the reference)");
  }
}

// The current technique's statistics (FrameStats) or the reference's passes, and the difference
// view's numbers.
void Viewer::draw_progress() {
  section("progress");
  if (const Technique* t = live(technique_)) {
    // Every frame-by-frame technique's statistics in the one form of FrameStats.
    const TechniqueInfo& info = technique_info(technique_);
    const FrameStats s = t->frame_stats();
    if (info.frame_snapshots) {
      ImGui::Text("frames %d / %d%s", s.frames, settings_.frames,
                  t->converged() ? "  (converged)" : "");
    } else {
      ImGui::Text("frame %d", s.frames);
    }
    for (const auto& [pass, ms] : s.pass_ms) ImGui::Text("%-12s%8.2f ms", pass.c_str(), ms);
    ImGui::Text("window frame %7.1f ms", frame_ms_);
    for (const std::string& note : s.notes) ImGui::TextUnformatted(note.c_str());
    if (!info.physically_based)
      ImGui::TextDisabled("not physically based: D compares it after a best scale");
  } else {
    if (technique_ == TechniqueId::kPathtrace) {
      ImGui::Text("path tracer passes %d (%d paths per pixel each)", reference_passes_,
                  options_.pathtrace.pixel_samples);
    } else {
      ImGui::Text("reference passes %d (%d probes per pixel each)", reference_passes_,
                  options_.reference.pixel_samples);
    }
    if (!reference_error_.empty()) ImGui::TextWrapped("%s", reference_error_.c_str());
  }
  if (!on_cpu()) {
    const std::string label = "difference vs " + cached_label_ + " (D)";
    ImGui::Checkbox(label.c_str(), &show_difference_);
    if (show_difference_) ImGui::TextWrapped("%s", difference_text_.c_str());
  }
}

// Per channel: the mean free path 1 / sigma_t' (mm) and the reduced albedo alpha'; and eta, g.
// Applied when a slider is let go: the maps get the new material, the reference restarts.
void Viewer::draw_material_controls() {
  materials::Material m = scene_.material;
  bool changed = false;
  static const char* kChannel[3] = {"R", "G", "B"};
  for (int c = 0; c < 3; ++c) {
    const double st = m.sigma_a[std::size_t(c)] + m.sigma_s_reduced[std::size_t(c)];
    float mfp = st > 0 ? float(1.0 / st) : 1e3f;
    float albedo = st > 0 ? float(m.sigma_s_reduced[std::size_t(c)] / st) : 0.0f;
    ImGui::PushID(c);
    ImGui::SetNextItemWidth(60 * ImGui::GetIO().FontGlobalScale);
    ImGui::SliderFloat("##mfp", &mfp, 0.001f, 100.0f, "%.3g mm", ImGuiSliderFlags_Logarithmic);
    bool edited = slider_done();
    ImGui::SameLine();
    ImGui::SetNextItemWidth(60 * ImGui::GetIO().FontGlobalScale);
    ImGui::SliderFloat("##albedo", &albedo, 0.0f, 0.99999f, "%.5f");
    edited |= slider_done();
    ImGui::SameLine();
    ImGui::Text("%s mfp, albedo", kChannel[c]);
    ImGui::PopID();
    if (edited) {
      const double t = 1.0 / std::max(mfp, 1e-6f);
      m.sigma_s_reduced[std::size_t(c)] = albedo * t;
      m.sigma_a[std::size_t(c)] = (1.0 - albedo) * t;
      changed = true;
    }
  }
  float eta = float(m.ior);
  ImGui::SliderFloat("eta", &eta, 1.0f, 2.0f, "%.3f");
  if (slider_done()) {
    m.ior = eta;
    changed = true;
  }
  float g = m.g ? float((*m.g)[0]) : 0.0f;
  ImGui::SliderFloat("g", &g, 0.0f, 0.95f, "%.2f");
  if (slider_done()) {
    m.g = materials::Rgb{g, g, g};
    changed = true;
  }
  if (changed) {
    m.name = scene_.material.name + " (edited)";
    m.sigma_s.reset();
    if (m.g) {
      m.sigma_s = materials::Rgb{};
      for (int c = 0; c < 3; ++c)
        (*m.sigma_s)[std::size_t(c)] = m.sigma_s_reduced[std::size_t(c)] / (1 - (*m.g)[std::size_t(c)]);
    }
    apply_material(m);
  }
}

void Viewer::apply_material(const materials::Material& material) {
  const materials::Material previous = scene_.material;
  scene_.material = material;
  try {
    ++versions_.material;
  } catch (const Error& e) {  // e.g. the tabulated model outside its table
    message_ = e.what();
    scene_.material = previous;
    ++versions_.material;
    return;
  }
  message_ = "material: " + scene_.material.name;
  scene_changed();
}

}  // namespace lucent::render::viewer_detail
