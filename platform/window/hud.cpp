#include "engine/ir_report.hpp"
#include "platform/window/hud.hpp"

#include <imgui.h>
#include <imgui_impl_glfw.h>
#include <imgui_impl_vulkan.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

namespace fire::window {

namespace {

VkResult g_backend_failure = VK_SUCCESS;  // the first failed VkResult inside ImGui's Vulkan backend

void on_backend_result(VkResult r) {
  if (r != VK_SUCCESS && g_backend_failure == VK_SUCCESS) g_backend_failure = r;
}

}  // namespace

Result<std::unique_ptr<Hud>> Hud::create(render::Context& context, render::Presenter& presenter, Window& window) {
  using R = Result<std::unique_ptr<Hud>>;
  std::unique_ptr<Hud> hud(new Hud);
  hud->device_ = context.device();
  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGuiIO& io = ImGui::GetIO();
  io.IniFilename = nullptr;  // no imgui.ini left in the working directory
  ImGui::StyleColorsDark();
  ImGui::GetStyle().Alpha = 0.92f;
  if (presenter.srgb())  // ImGui's colours are sRGB values: written to an sRGB image they must be linear first
    for (ImVec4& c : ImGui::GetStyle().Colors)
      for (float* v : {&c.x, &c.y, &c.z}) *v = *v <= 0.04045f ? *v / 12.92f : std::pow((*v + 0.055f) / 1.055f, 2.4f);
  hud->glfw_ = ImGui_ImplGlfw_InitForVulkan(window.handle(), true);
  if (!hud->glfw_) return R::failure("ImGui_ImplGlfw_InitForVulkan failed");

  // One combined image sampler: the font atlas.
  VkDescriptorPoolSize size{VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1};
  VkDescriptorPoolCreateInfo pool{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
  pool.flags = VK_DESCRIPTOR_POOL_CREATE_FREE_DESCRIPTOR_SET_BIT;
  pool.maxSets = 1;
  pool.poolSizeCount = 1;
  pool.pPoolSizes = &size;
  if (VkResult r = vkCreateDescriptorPool(context.device(), &pool, nullptr, &hud->pool_); r != VK_SUCCESS)
    return R::failure(render::vk_failure("vkCreateDescriptorPool", r));

  ImGui_ImplVulkan_InitInfo info{};
  info.Instance = context.instance();
  info.PhysicalDevice = context.physical_device();
  info.Device = context.device();
  info.QueueFamily = context.queue_family();
  info.Queue = context.queue();
  info.DescriptorPool = hud->pool_;
  info.Subpass = 0;
  // The backend rotates its vertex buffers over ImageCount frames; the presenter keeps one frame in flight.
  info.MinImageCount = 2;
  info.ImageCount = 2;
  info.MSAASamples = VK_SAMPLE_COUNT_1_BIT;
  info.CheckVkResultFn = on_backend_result;
  hud->vulkan_ = ImGui_ImplVulkan_Init(&info, presenter.overlay_pass());
  if (!hud->vulkan_) return R::failure("ImGui_ImplVulkan_Init failed");
  if (Status s = presenter.run_once([](VkCommandBuffer cmd) { ImGui_ImplVulkan_CreateFontsTexture(cmd); }); !s)
    return R::failure("the HUD's font upload: " + s.error);
  ImGui_ImplVulkan_DestroyFontUploadObjects();
  if (Status s = hud->status(); !s) return R::failure(s.error);
  return hud;
}

Hud::~Hud() {
  if (device_) vkDeviceWaitIdle(device_);  // nothing else to do on failure: everything is destroyed either way
  if (vulkan_) ImGui_ImplVulkan_Shutdown();
  if (glfw_) ImGui_ImplGlfw_Shutdown();
  if (ImGui::GetCurrentContext()) ImGui::DestroyContext();
  if (pool_) vkDestroyDescriptorPool(device_, pool_, nullptr);
}

Status Hud::status() const {
  if (g_backend_failure == VK_SUCCESS) return Status::success();
  return Status::failure(std::string("a Vulkan call in ImGui's Vulkan backend failed: ") +
                         render::vk_result_name(g_backend_failure));
}

bool Hud::covers(double x, double y) const {
  return std::any_of(panels_.begin(), panels_.end(),
                     [&](const Panel& p) { return x >= p.x0 && x < p.x1 && y >= p.y0 && y < p.y1; });
}

namespace {

// The camera's 1024 x 768 image at `scale`, its blobs as discs that grow with their size, strays orange;
// framed green while it sees the pen, red while it does not. For fire aim, also the working volume's cells
// (teal where both cameras see it, dim red where only this one does) and the lines under the title.
void draw_camera(int camera, const CameraView& view, float scale) {
  const float width = kWiimoteWidth * scale, height = kWiimoteHeight * scale;
  ImGui::BeginGroup();
  ImGui::Text("camera %d: %s", camera, view.pen_seen ? "pen seen" : "no light");
  for (const std::string& line : view.lines) ImGui::TextUnformatted(line.c_str());
  const ImVec2 corner = ImGui::GetCursorScreenPos();
  ImDrawList* draw = ImGui::GetWindowDrawList();
  const ImU32 frame = view.pen_seen ? IM_COL32(90, 220, 110, 255) : IM_COL32(230, 90, 80, 255);
  draw->AddRectFilled(corner, ImVec2(corner.x + width, corner.y + height), IM_COL32(15, 15, 20, 230));
  if (view.volume_columns > 0) {
    const float cell = float(kWiimoteWidth) / float(view.volume_columns) * scale;
    for (size_t k = 0; k < view.volume.size(); ++k) {
      if (view.volume[k] == 0) continue;
      const ImVec2 a(corner.x + float(k % size_t(view.volume_columns)) * cell,
                     corner.y + float(k / size_t(view.volume_columns)) * cell);
      draw->AddRectFilled(a, ImVec2(a.x + cell, a.y + cell),
                          view.volume[k] == 2 ? IM_COL32(16, 64, 58, 255) : IM_COL32(72, 30, 28, 255));
    }
  }
  draw->AddRect(corner, ImVec2(corner.x + width, corner.y + height), frame);
  // The app's eighth-size view keeps its small discs; larger views grow them with the image (fire aim's PNGs').
  auto radius = [&](const IrBlob& b) { return std::max(2.0f + float(b.size) * 0.5f, (6.0f + 2.0f * float(b.size)) * scale); };
  const ImU32 orange = IM_COL32(255, 140, 0, 255);
  for (const IrBlob& b : view.strays)
    draw->AddCircleFilled(ImVec2(corner.x + b.x * scale, corner.y + b.y * scale), radius(b), orange);
  for (const IrBlob& b : view.blobs)
    draw->AddCircleFilled(ImVec2(corner.x + b.x * scale, corner.y + b.y * scale), radius(b),
                          b.stray ? orange : IM_COL32(255, 255, 255, 255));
  ImGui::Dummy(ImVec2(width, height));
  ImGui::EndGroup();
}

constexpr ImGuiWindowFlags kFixed = ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_AlwaysAutoResize |
                                    ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_NoFocusOnAppearing |
                                    ImGuiWindowFlags_NoNav | ImGuiWindowFlags_NoMove;

// The current window's rectangle, kept so that a press can be told to be on the HUD when it happens.
void keep_panel(std::vector<Panel>& panels) {
  const ImVec2 at = ImGui::GetWindowPos(), size = ImGui::GetWindowSize();
  panels.push_back({at.x, at.y, at.x + size.x, at.y + size.y});
}

// fire aim: the lines, the problems in red (or a green line saying there are none), both camera views side by
// side at up to half the sensor's size, smaller when the window is narrow.
void build_aiming(const HudData& d, std::vector<Panel>& panels) {
  ImGui::SetNextWindowPos(ImVec2(10, 10), ImGuiCond_Always);
  ImGui::SetNextWindowBgAlpha(0.9f);
  ImGui::Begin("FIRE aim", nullptr, kFixed);
  for (const std::string& line : d.live) ImGui::TextUnformatted(line.c_str());
  if (d.problems.empty()) ImGui::TextColored(ImVec4(0.5f, 0.9f, 0.55f, 1.0f), "no problems");
  for (const std::string& p : d.problems) {
    ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1.0f, 0.5f, 0.4f, 1.0f));
    ImGui::PushTextWrapPos(ImGui::GetIO().DisplaySize.x - 40);
    ImGui::TextUnformatted(p.c_str());
    ImGui::PopTextWrapPos();
    ImGui::PopStyleColor();
  }
  const ImGuiStyle& style = ImGui::GetStyle();
  const float room = ImGui::GetIO().DisplaySize.x - 20 - 2 * style.WindowPadding.x - style.ItemSpacing.x;
  const float scale = std::clamp(room / (2.0f * kWiimoteWidth), 1.0f / 8.0f, 0.5f);
  draw_camera(0, d.cameras[0], scale);
  ImGui::SameLine();
  draw_camera(1, d.cameras[1], scale);
  keep_panel(panels);
  ImGui::End();
}

}  // namespace

void Hud::build(const HudData& d) {
  ImGui_ImplVulkan_NewFrame();
  ImGui_ImplGlfw_NewFrame();
  ImGui::NewFrame();

  panels_.clear();
  if (d.aiming) {
    build_aiming(d, panels_);
    ImGui::Render();
    return;
  }
  ImGui::SetNextWindowPos(ImVec2(10, 10), ImGuiCond_Always);
  ImGui::SetNextWindowBgAlpha(0.75f);
  ImGui::Begin("FIRE", nullptr, kFixed);
  ImGui::Text("frame %.1f ms   system frames %llu", d.frame_ms, static_cast<unsigned long long>(d.frames));
  if (d.timings && ImGui::BeginTable("timings", 4, ImGuiTableFlags_SizingFixedFit)) {
    ImGui::TableSetupColumn("system");
    ImGui::TableSetupColumn("mean us");
    ImGui::TableSetupColumn("p99 us");
    ImGui::TableSetupColumn("max us");
    ImGui::TableHeadersRow();
    auto row = [](const SystemTiming& t) {
      ImGui::TableNextRow();
      ImGui::TableNextColumn();
      ImGui::TextUnformatted(t.name.c_str());
      ImGui::TableNextColumn();
      ImGui::Text("%.0f", t.mean_ns() / 1e3);
      ImGui::TableNextColumn();
      ImGui::Text("%.0f", double(t.percentile_ns(99)) / 1e3);
      ImGui::TableNextColumn();
      ImGui::Text("%.0f", double(t.max_ns) / 1e3);
    };
    for (const SystemTiming& t : *d.timings) row(t);
    if (d.frame_timing) row(*d.frame_timing);
    ImGui::EndTable();
  }
  ImGui::Separator();
  ImGui::Text("vertices %zu  edges %zu  faces %zu", d.vertices, d.edges, d.faces);
  ImGui::Text("border loops %zu%s", d.border_loops, d.border_loops == 0 && d.faces > 0 ? " (closed)" : "");
  if (d.pending_bridges > 0)
    ImGui::TextWrapped("%zu curve(s) between two border loops: no surface between them until a second curve joins the same two loops",
                       d.pending_bridges);
  if (d.pending_pieces > 0)
    ImGui::TextWrapped("%zu stroke piece(s) pending: go on from the free end to a curve (undo takes off the last piece)",
                       d.pending_pieces);
  ImGui::Text("points %zu  surface quads %zu", d.points, d.surface_quads);
  ImGui::Text("mode: %s", d.border_mode ? "border (strokes extend the border)" : "split (strokes split faces)");
  ImGui::Text("view: surface %s  curves %s  wireframe %s", d.view.surface ? "on" : "off", d.view.curves ? "on" : "off",
              !d.wireframe_supported ? "n/a" : d.view.wireframe ? "on" : "off");
  if (!d.last_rejection.empty()) {
    ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1.0f, 0.55f, 0.45f, 1.0f));
    ImGui::TextWrapped("rejected: %s", d.last_rejection.c_str());
    ImGui::PopStyleColor();
  }
  if (!d.status.empty()) ImGui::TextUnformatted(d.status.c_str());
  if (!d.live.empty()) {
    ImGui::Separator();
    for (const std::string& line : d.live) ImGui::TextUnformatted(line.c_str());
  }
  if (d.cameras[0].present) draw_camera(0, d.cameras[0], 1.0f / 8.0f);
  if (d.cameras[0].present && d.cameras[1].present) ImGui::SameLine();
  if (d.cameras[1].present) draw_camera(1, d.cameras[1], 1.0f / 8.0f);
  ImGui::TextDisabled("H: help");
  const float panel_right = ImGui::GetWindowPos().x + ImGui::GetWindowSize().x;
  keep_panel(panels_);
  ImGui::End();

  if (d.help) {
    const ImVec2 size = ImGui::GetIO().DisplaySize;
    const ImGuiStyle& style = ImGui::GetStyle();
    ImGui::SetNextWindowPos(ImVec2(size.x - 10, 10), ImGuiCond_Always, ImVec2(1.0f, 0.0f));
    ImGui::SetNextWindowBgAlpha(0.85f);
    ImGui::Begin("Keys", nullptr, kFixed);
    ImGui::TextUnformatted("Keys and mouse");
    ImGui::Separator();
    // Each line is "key  description": the keys in a column, the descriptions wrapped to the room right of the
    // panel above, so that in a narrow window the help does not cover the panel's figures.
    std::vector<std::pair<std::string, std::string>> rows;
    float key_width = 0;
    for (const std::string& line : d.keys) {
      const size_t gap = line.find("  ");
      const size_t text = gap == std::string::npos ? std::string::npos : line.find_first_not_of(' ', gap);
      rows.emplace_back(line.substr(0, gap), text == std::string::npos ? std::string() : line.substr(text));
      key_width = std::max(key_width, ImGui::CalcTextSize(rows.back().first.c_str()).x);
    }
    const float column = key_width + 2 * style.ItemSpacing.x;
    const float room = size.x - 10 - panel_right - 10 - 2 * style.WindowPadding.x - column;
    const float wrap = std::max(room, ImGui::CalcTextSize("a description wraps here").x);
    for (const auto& [key, text] : rows) {
      ImGui::TextUnformatted(key.c_str());
      ImGui::SameLine(style.WindowPadding.x + column);
      ImGui::PushTextWrapPos(ImGui::GetCursorPosX() + wrap);
      ImGui::TextUnformatted(text.c_str());
      ImGui::PopTextWrapPos();
    }
    keep_panel(panels_);
    ImGui::End();
  }
  ImGui::Render();
}

void Hud::draw(VkCommandBuffer cmd) { ImGui_ImplVulkan_RenderDrawData(ImGui::GetDrawData(), cmd); }

}  // namespace fire::window
