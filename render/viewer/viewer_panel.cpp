// The viewer's panel (Dear ImGui): material, model and technique, the radiance maps' knobs, the
// scene, progress and the difference against the reference (viewer_impl.h).
#include "area_light.h"
#include "viewer_impl.h"

#include <imgui_internal.h>  // the panel's widest line (ImGuiWindow::DC.CursorMaxPos)

#include "lucent/materials/albedo.h"
#include "lucent/materials/dipole.h"

namespace lucent::render::viewer_detail {
namespace {

bool slider_done() { return ImGui::IsItemDeactivatedAfterEdit(); }

// Before a radio button or checkbox labelled `label` after another: on the same line when it fits
// in the panel, else on the next (a row of them ran past a narrow panel's edge).
void same_line_if_fits(const char* label) {
  const ImGuiStyle& style = ImGui::GetStyle();
  const float width =
      ImGui::GetFrameHeight() + style.ItemInnerSpacing.x + ImGui::CalcTextSize(label).x;
  const float right = ImGui::GetItemRectMax().x + style.ItemSpacing.x + width;
  if (right <= ImGui::GetWindowPos().x + ImGui::GetWindowContentRegionMax().x) ImGui::SameLine();
}

void section(const char* title) {
  ImGui::Separator();
  ImGui::TextDisabled("%s", title);
}

}  // namespace

void Viewer::draw_ui() {
  // Docked at the left, as high as the window, the image beside it (view_rect): it never covers
  // the object. Its width is the person's (drag its right edge), from what a slider and its label
  // need to 60% of the window; folded to its title bar (click it) or hidden (H).
  const float font = ImGui::GetFontSize();
  const float min_width = std::min(22.0f * font, 0.6f * float(width_));
  ImGui::SetNextWindowPos(ImVec2(0, 0), ImGuiCond_Always);
  ImGui::SetNextWindowSize(ImVec2(default_panel_width(), float(height_)), ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowSizeConstraints(
      ImVec2(min_width, float(height_)),
      ImVec2(std::max(min_width, 0.6f * float(width_)), float(height_)));
  ImGui::SetNextWindowCollapsed(panel_collapsed_, ImGuiCond_FirstUseEver);
  const bool open = ImGui::Begin("lucent", nullptr, ImGuiWindowFlags_NoMove);
  panel_collapsed_ = ImGui::IsWindowCollapsed();
  panel_width_ = ImGui::GetWindowWidth();
  panel_bar_height_ = ImGui::GetFrameHeight();
  if (open) {
    // Sliders take what is left after 9 characters of label.
    ImGui::PushItemWidth(-9.0f * font);
    draw_choices();
    draw_maps_knobs();
    draw_scene_controls();
    draw_progress();
    if (!message_.empty()) ImGui::TextWrapped("%s", message_.c_str());
    ImGui::Separator();
    ImGui::PushStyleColor(ImGuiCol_Text, ImGui::GetStyleColorVec4(ImGuiCol_TextDisabled));
    ImGui::TextWrapped("drag: orbit; right drag: light; wheel: zoom");
    ImGui::TextWrapped(
        "S screenshot, R restart, H hide the panel, E exposure, D difference, Esc "
        "quit");
    ImGui::PopStyleColor();
    ImGui::PopItemWidth();
    // The widest line drawn: a label wider than the panel would be cut at its edge.
    panel_content_width_ = ImGui::GetCurrentWindow()->DC.CursorMaxPos.x - ImGui::GetWindowPos().x;
    panel_inner_width_ = ImGui::GetWindowContentRegionMax().x;
  }
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
    if (!first) same_line_if_fits(t.panel_label.c_str());
    first = false;
    if (ImGui::RadioButton(t.panel_label.c_str(), &technique, int(t.id))) set_technique(t.id);
  }
  if (technique_ == TechniqueId::kFur) ImGui::Checkbox("rotating lobe light (L)", &fur_lobe_);
  int model = settings_.model == DiffusionModel::kDirectionalDipole ? 0
              : settings_.model == DiffusionModel::kDipole          ? 1
                                                                    : 2;
  if (ImGui::RadioButton("ddipole", &model, 0) || (same_line_if_fits("dipole"), false) ||
      ImGui::RadioButton("dipole", &model, 1) || (same_line_if_fits("tabulated"), false) ||
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
      // A knob moved by hand is kept at every level of the frame budget.
      if (pending_.frames != settings_.frames) mark_explicit("maps-frames");
      if (pending_.directions != settings_.directions) mark_explicit("maps-directions");
      if (pending_.samples != settings_.samples) mark_explicit("maps-samples");
      if (pending_.radiance_map_size != settings_.radiance_map_size)
        mark_explicit("maps-radiance-map");
      if (pending_.light_map_size != settings_.light_map_size) mark_explicit("maps-light-map");
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
  bool ground = scene_.ground.has_value();
  if (ImGui::Checkbox("ground", &ground)) {
    // A Lambertian plane under the object, shadowed by it (the maps draw it).
    if (ground) {
      scene_.ground = Vec3f(0.5f, 0.5f, 0.5f);
    } else {
      scene_.ground.reset();
    }
    rebuild_maps();  // its program is built with the maps' (the levels set up before drop)
  }
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
      ImGui::Text("frames %d / %d%s", s.frames, running_settings().frames,
                  t->converged() ? "  (converged)" : "");
    } else {
      ImGui::Text("frame %d", s.frames);
    }
    // The passes in two columns: a long pass name ran into its time ("radiance map16853.03 ms").
    if (ImGui::BeginTable("passes", 2, ImGuiTableFlags_SizingStretchProp)) {
      for (const auto& [pass, ms] : s.pass_ms) {
        ImGui::TableNextRow();
        ImGui::TableNextColumn();
        ImGui::TextUnformatted(pass.c_str());
        ImGui::TableNextColumn();
        ImGui::Text("%.2f ms", ms);
      }
      ImGui::TableNextRow();
      ImGui::TableNextColumn();
      ImGui::TextUnformatted("window frame");
      ImGui::TableNextColumn();
      ImGui::Text("%.1f ms", frame_ms_);
      ImGui::EndTable();
    }
    if (technique_ == TechniqueId::kMaps && frame_budget_ms_ > 0) {
      const RenderSettings running = running_settings();
      ImGui::TextWrapped("quality level %d of %d for a %g ms frame: %s%s", level_ + 1,
                         int(maps_quality_ladder(settings_, fixed_).size()), frame_budget_ms_,
                         quality_text(running).c_str(),
                         render_scale_ < 1
                             ? (", at " + std::to_string(int(std::lround(100 * render_scale_))) +
                                "% resolution while it refines")
                                   .c_str()
                             : "");
    }
    for (const std::string& note : s.notes) ImGui::TextWrapped("%s", note.c_str());
    if (!info.physically_based)
      ImGui::TextWrapped("not physically based: D compares it after a best scale");
  } else {
    if (technique_ == TechniqueId::kPathtrace) {
      ImGui::TextWrapped("path tracer passes %d (%d paths per pixel each)", reference_passes_,
                         options_.pathtrace.pixel_samples);
    } else {
      ImGui::TextWrapped("reference passes %d (%d probes per pixel each)", reference_passes_,
                         options_.reference.pixel_samples);
    }
    if (!reference_error_.empty()) ImGui::TextWrapped("%s", reference_error_.c_str());
  }
  if (!on_cpu()) {
    const std::string label = "difference vs " + cached_label_ + " (D)";
    if (ImGui::Checkbox(label.c_str(), &show_difference_) && show_difference_) set_render_scale(1);
    if (show_difference_) ImGui::TextWrapped("%s", difference_text_.c_str());
  }
}

// The material in an artist's terms, per channel: its diffuse colour (the standard dipole's total
// diffuse reflectance, what a flat slab of it reflects) and its mean free path (the diffuse mean
// free path 1 / sigma_tr, mm: how far light bleeds; the one "mean free path" of lucent's material
// files, `lucent materials` and this panel), inverted as materials::coefficients_from_diffuse_
// colour; or its coefficients sigma_a and sigma_s' (mm^-1). Then eta and g, and saving it.
// Applied when a control is let go: the maps get the new material, the reference restarts.
void Viewer::draw_material_controls() {
  materials::Material m = scene_.material;
  bool changed = false;
  ImGui::Checkbox("edit coefficients", &edit_coefficients_);
  if (edit_coefficients_) {
    draw_coefficient_controls(m, changed);
  } else {
    float colour[3], mfp[3];
    for (int c = 0; c < 3; ++c) {
      const materials::StandardDipole<double> dipole(m.medium(c));
      colour[c] = float(dipole.total_diffuse_reflectance());
      const double sigma_tr = dipole.coefficients().sigma_tr;
      mfp[c] = sigma_tr > 0 ? float(1 / sigma_tr) : 1e4f;
    }
    ImGui::ColorEdit3("colour", colour, ImGuiColorEditFlags_Float);
    bool edited = slider_done();
    ImGui::DragFloat3("mfp mm", mfp, 0.01f, 1e-3f, 1e4f, "%.3g", ImGuiSliderFlags_Logarithmic);
    edited |= slider_done();
    if (ImGui::IsItemHovered())
      ImGui::SetTooltip("mean free path per channel: the diffuse mean free path 1/sigma_tr (mm)");
    if (edited) {
      try {
        for (int c = 0; c < 3; ++c) {
          const materials::ReducedCoefficients k = materials::coefficients_from_diffuse_colour(
              std::clamp(double(colour[c]), 1e-4, 0.9999), std::max(double(mfp[c]), 1e-3), m.ior);
          m.sigma_a[std::size_t(c)] = k.sigma_a;
          m.sigma_s_reduced[std::size_t(c)] = k.sigma_s_reduced;
        }
        changed = true;
      } catch (const Error& e) {
        message_ = e.what();
      }
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
    m.name = scene_.material.name.find(" (edited)") == std::string::npos
                 ? scene_.material.name + " (edited)"
                 : scene_.material.name;
    m.sigma_s.reset();
    if (m.g) {
      m.sigma_s = materials::Rgb{};
      for (int c = 0; c < 3; ++c)
        (*m.sigma_s)[std::size_t(c)] = m.sigma_s_reduced[std::size_t(c)] / (1 - (*m.g)[std::size_t(c)]);
    }
    apply_material(m);
  }
  if (save_path_[0] == '\0') std::snprintf(save_path_.data(), save_path_.size(), "edited.json");
  ImGui::InputText("##save", save_path_.data(), save_path_.size());
  ImGui::SameLine();
  if (ImGui::Button("save")) save_material(save_path_.data());
}

void Viewer::draw_coefficient_controls(materials::Material& m, bool& changed) {
  float sigma_a[3], sigma_s[3];
  for (int c = 0; c < 3; ++c) {
    sigma_a[c] = float(m.sigma_a[std::size_t(c)]);
    sigma_s[c] = float(m.sigma_s_reduced[std::size_t(c)]);
  }
  ImGui::DragFloat3("sigma_a /mm", sigma_a, 0.001f, 0.0f, 1e3f, "%.4g",
                    ImGuiSliderFlags_Logarithmic);
  bool edited = slider_done();
  ImGui::DragFloat3("sigma_s' /mm", sigma_s, 0.01f, 0.0f, 1e4f, "%.4g",
                    ImGuiSliderFlags_Logarithmic);
  edited |= slider_done();
  if (edited) {
    for (int c = 0; c < 3; ++c) {
      m.sigma_a[std::size_t(c)] = std::max(0.0f, sigma_a[c]);
      m.sigma_s_reduced[std::size_t(c)] = std::max(0.0f, sigma_s[c]);
    }
    changed = true;
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
  auto_exposure_ = true;
  scene_changed();
}

}  // namespace lucent::render::viewer_detail
