// fire eval: distance of a reconstructed surface to the limit surface of its control mesh (issue 3, item 6).
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

#include "platform/files.hpp"
#include "platform/network_file.hpp"
#include "platform/obj.hpp"
#include "platform/surface_io.hpp"
#include "systems/evaluate/evaluate.hpp"
#include "systems/tracking/registration.hpp"
#include "tools/app/session_rig.hpp"
#include "tools/fire/commands.hpp"

namespace fire::cli {

namespace {

struct EvalArgs {
  std::string surface_path, reference_path, network_path;
  std::vector<std::string> align_paths;  // TRUE.json MEASURED.json, or none
  int reference_levels = 5;
  double spacing = 0.002;  // sample spacing, a fraction of the reference diagonal
  double crease_radius = 0.01;  // where the bend across a sharp curve is read, a fraction of the reference diagonal
};

int fail(const std::string& message) {
  std::cerr << "fire eval: " << message << "\n";
  return 1;
}

// A line per stage on a terminal: subdividing the reference and sampling both surfaces take seconds.
class Stages {
 public:
  void done(const std::string& what) const {
    if (!on_terminal_) return;
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started_).count();
    char elapsed[32];
    std::snprintf(elapsed, sizeof elapsed, " (%.1f s)", seconds);
    std::cerr << "fire eval: " << what << elapsed << "\n";
  }

 private:
  bool on_terminal_ = ::isatty(STDERR_FILENO) != 0;
  std::chrono::steady_clock::time_point started_ = std::chrono::steady_clock::now();
};

// How far the surface bends across each curve marked sharp, against the reference there: read every `radius`
// along the curve, away from its ends (a corner bends two ways), on both surfaces at the same radius.
struct CreasePoint {
  uint32_t edge = 0, point = 0;
  double surface_deg = 0, reference_deg = 0, error_deg = -1;
};
struct Creases {
  size_t curves = 0, points = 0;
  CreasePoint worst;
};
Creases measure_creases(const Mesh& network, const evaluate::TriangleBvh& surface, const evaluate::TriangleBvh& reference, double radius) {
  Creases out;
  for (EdgeIndex e{0}; e < network.edge_slots(); ++e) {
    if (!network.edge_alive(e) || !(network.edges.flags[e] & kSharpEdge)) continue;
    ++out.curves;
    const auto line = network.polyline(e);
    std::vector<double> arc(line.size(), 0);
    for (size_t i = 1; i < line.size(); ++i) arc[i] = arc[i - 1] + (line[i] - line[i - 1]).norm();
    double next = 3 * radius;
    for (size_t i = 1; i + 1 < line.size(); ++i) {
      if (arc[i] < next || arc[i] > arc.back() - 3 * radius) continue;
      next = arc[i] + radius;
      const Vec3 tangent = line[i + 1] - line[i - 1];
      const std::optional<double> on_surface = evaluate::bend_across_deg(surface, line[i], tangent, radius);
      const std::optional<double> on_reference = evaluate::bend_across_deg(reference, reference.closest(line[i]).point, tangent, radius);
      if (!on_surface || !on_reference) continue;
      ++out.points;
      const double error = std::abs(*on_surface - *on_reference);
      if (error > out.worst.error_deg) out.worst = {e, static_cast<uint32_t>(i), *on_surface, *on_reference, error};
    }
  }
  return out;
}

// The rigid motion from the frame the marks were measured in to the object's (marks matched by id).
Result<tracking::RigidTransform> alignment(const std::string& true_path, const std::string& measured_path, size_t& matched) {
  using R = Result<tracking::RigidTransform>;
  std::vector<IdentifiedMark> files[2];
  for (int k = 0; k < 2; ++k) {
    const std::string& path = k == 0 ? true_path : measured_path;
    auto text = read_text_file(path);
    if (!text) return R::failure(text.error());
    auto marks = identified_marks_from_json(*text, path);
    if (!marks) return R::failure(marks.error());
    files[k] = std::move(*marks);
  }
  std::vector<Vec3> measured, object;
  for (const IdentifiedMark& m : files[1])
    for (const IdentifiedMark& t : files[0])
      if (t.id == m.id) {
        measured.push_back(m.p);
        object.push_back(t.p);
      }
  matched = measured.size();
  if (matched < 3)
    return R::failure("--align: " + std::to_string(matched) + " mark id(s) of " + measured_path + " are in " + true_path +
                      ", at least 3 are needed");
  auto T = tracking::register_rigid(measured, object);
  if (!T) return R::failure("--align: the marks matched cannot be aligned: " + T.error());
  return T;
}

int run_eval(const EvalArgs& a) {
  const Stages stages;
  auto surface = read_surface(a.surface_path);
  if (!surface) return fail(surface.error());
  std::optional<tracking::RigidTransform> aligned;
  size_t align_marks = 0;
  if (!a.align_paths.empty()) {
    auto T = alignment(a.align_paths[0], a.align_paths[1], align_marks);
    if (!T) return fail(T.error());
    aligned = *T;
  }
  auto out_mesh = evaluate::triangulate(surface->positions, surface->face_offsets, surface->face_vertices);
  if (!out_mesh) return fail(a.surface_path + ": " + out_mesh.error());

  auto control_text = read_text_file(a.reference_path);
  if (!control_text) return fail(control_text.error());
  auto control = parse_obj(*control_text, a.reference_path);
  if (!control) return fail(control.error());
  // The reference into SURFACE's frame, by the inverse motion: the same distances, and the positions printed
  // are where they are in SURFACE and the network.
  if (aligned)
    for (Vec3& p : control->positions) p = aligned->R.transpose() * (p - aligned->t);
  // A cage from fire reconstruct --cage, or one of OpenSubdiv's shapes, says which edges are creases.
  auto tags = parse_obj_tags(*control_text, a.reference_path, *control);
  if (!tags) return fail(tags.error());
  auto reference = evaluate::reference_limit_surface(control->positions, control->face_offsets, control->face_vertices,
                                                     a.reference_levels, tags->sharp_edges, tags->border_corners);
  if (!reference) return fail(a.reference_path + ": reference mesh cannot be subdivided: " + reference.error());
  const double diagonal = bounding_box_diagonal(reference->positions);
  if (!(diagonal > 0) || !std::isfinite(diagonal))
    return fail(a.reference_path + ": the reference limit surface has no extent (bounding-box diagonal " +
                std::to_string(diagonal) + ")");
  stages.done(a.reference_path + ": limit surface at " + std::to_string(a.reference_levels) + " levels, " +
              std::to_string(reference->triangle_count()) + " triangles; measuring both ways");

  std::vector<Vec3> network_points;
  std::vector<std::pair<uint32_t, uint32_t>> network_point_ids;  // (edge, index in its polyline) per point
  std::optional<Mesh> network;
  if (!a.network_path.empty()) {
    auto loaded = load_network(a.network_path);
    if (!loaded) return fail(loaded.error());
    network = std::move(*loaded);
    for (EdgeIndex e{0}; e < network->edge_slots(); ++e)
      if (network->edge_alive(e)) {
        const auto polyline = network->polyline(e);
        for (uint32_t i = 0; i < polyline.size(); ++i) {
          network_points.push_back(polyline[i]);
          network_point_ids.emplace_back(e, i);
        }
      }
    if (network_points.empty()) return fail(a.network_path + ": the network has no polyline points");
  }

  const evaluate::TriangleBvh out_bvh(*out_mesh), reference_bvh(*reference);
  const evaluate::SurfaceDistance d =
      evaluate::surface_distance(*out_mesh, out_bvh, *reference, reference_bvh, a.spacing * diagonal, diagonal);
  if (!std::isfinite(d.rms) || !std::isfinite(d.hausdorff))
    return fail(a.surface_path + ": distances are not finite (rms " + std::to_string(d.rms) + ", hausdorff " +
                std::to_string(d.hausdorff) + ")");

  stages.done(std::to_string(d.a_to_b.samples + d.b_to_a.samples) + " samples measured");

  nlohmann::ordered_json out;
  out["rms"] = d.rms;
  out["hausdorff"] = d.hausdorff;
  out["hausdorff_at"] = {d.hausdorff_at.x(), d.hausdorff_at.y(), d.hausdorff_at.z()};
  // From SURFACE's samples only: what a drawing that covers part of the object is measured by.
  out["surface_rms"] = d.a_to_b.rms() / diagonal;
  out["surface_max"] = d.a_to_b.max / diagonal;
  if (!network_points.empty()) {
    const evaluate::OneSided to_surface = evaluate::distances_to(network_points, out_bvh);
    const double network_max = to_surface.max / diagonal;
    if (!std::isfinite(network_max)) return fail(a.network_path + ": network distance is not finite");
    out["network_max"] = network_max;
    out["network_rms"] = to_surface.rms() / diagonal;
    const Vec3& worst = network_points[to_surface.max_index];
    out["network_max_at"] = {{"edge", network_point_ids[to_surface.max_index].first},
                             {"point", network_point_ids[to_surface.max_index].second},
                             {"position", {worst.x(), worst.y(), worst.z()}}};
  }
  if (network) {
    const Creases creases = measure_creases(*network, out_bvh, reference_bvh, a.crease_radius * diagonal);
    out["sharp_curves"] = creases.curves;
    if (creases.points > 0) {
      out["crease_points"] = creases.points;
      out["crease_error_max_deg"] = creases.worst.error_deg;
      out["crease_error_at"] = {{"edge", creases.worst.edge},
                                {"point", creases.worst.point},
                                {"surface_deg", creases.worst.surface_deg},
                                {"reference_deg", creases.worst.reference_deg}};
    }
  }
  // Counted on SURFACE's polygons and on the reference's control mesh, which has its limit surface's topology.
  const evaluate::Topology topology = evaluate::topology(surface->positions, surface->face_offsets, surface->face_vertices);
  const evaluate::Topology expected = evaluate::topology(control->positions, control->face_offsets, control->face_vertices);
  out["euler_characteristic"] = topology.euler_characteristic;
  out["border_loops"] = topology.border_loops;
  out["reference_euler_characteristic"] = expected.euler_characteristic;
  out["reference_border_loops"] = expected.border_loops;
  if (aligned) {
    out["align_marks"] = align_marks;
    out["align_residual"] = aligned->rms_residual;
  }
  out["diagonal"] = diagonal;
  out["samples"] = d.a_to_b.samples + d.b_to_a.samples;
  std::cout << out.dump() << "\n";
  return 0;
}

}  // namespace

void add_eval_commands(CLI::App& app, Registry& registry) {
  auto a = std::make_shared<EvalArgs>();
  CLI::App* cmd = app.add_subcommand(
      "eval",
      "Measure a surface against the Catmull-Clark limit surface of a control mesh. Both are sampled densely "
      "(vertices plus sub-triangle centroids); each sample's exact distance to the other surface is divided by the "
      "bounding-box diagonal of the reference limit surface. Prints one JSON line: rms (square root of the mean "
      "squared distance over the samples of both directions), hausdorff (largest distance, both directions) and "
      "hausdorff_at (the sample there), "
      "surface_rms and surface_max (the same from SURFACE's samples only: a drawing of part of the object is measured "
      "where it is), with --network network_max (largest distance from a polyline point to the surface), network_rms (their "
      "root mean square) and network_max_at (that point: its network edge, its index in the edge's polyline, its position), "
      "euler_characteristic and border_loops (SURFACE's, counted after welding coincident vertices; border loops are the "
      "connected pieces of the edges one face uses), reference_euler_characteristic and reference_border_loops (the "
      "control mesh's, which its limit surface has), diagonal, samples; with --network also sharp_curves (the network's "
      "curves marked sharp) and, where the bend across them could be read, crease_points and crease_error_max_deg, the "
      "largest difference between how far SURFACE and the reference bend across a sharp curve (180 degrees less the "
      "angle between the surface's two sides, read --crease-radius from the curve; 90 across a box's edge), with "
      "crease_error_at (edge, point, surface_deg, reference_deg); with --align, align_marks and align_residual (metres).");
  cmd->add_option("SURFACE", a->surface_path, "surface to measure: .obj, .ply, .stl or .glb as `fire reconstruct` writes")
      ->required();
  cmd->add_option("--reference", a->reference_path,
                  "control mesh (OBJ) whose limit surface is the ground truth; must be manifold. OpenSubdiv's tags in it "
                  "are honoured (t crease and t corner, infinitely sharp; t interpolateboundary 1 or 2), as `fire "
                  "reconstruct --cage` writes them")
      ->required();
  cmd->add_option("--network", a->network_path, "curve network whose polyline points are measured to SURFACE");
  cmd->add_option("--align", a->align_paths,
                  "TRUE.json MEASURED.json: marks files (fire-marks JSON) of the object's frame (fire simulate drawing "
                  "--marks-out) and of the frame its marks were measured in (fire replay --measured-marks-out); SURFACE "
                  "and --network are measured after the rigid motion (Umeyama, no scale) between the marks of the same id "
                  "(done by moving the reference the other way: positions printed stay in SURFACE's frame)")
      ->expected(2);
  cmd->add_option("--reference-levels", a->reference_levels,
                  "Catmull-Clark levels before projecting the reference to its limit")
      ->check(CLI::Range(5, 7))
      ->capture_default_str();
  cmd->add_option("--spacing", a->spacing, "sample spacing on both surfaces, as a fraction of the reference diagonal")
      ->check(CLI::Range(0.0005, 0.1))
      ->capture_default_str();
  cmd->add_option("--crease-radius", a->crease_radius,
                  "with --network: how far from a sharp curve the bend across it is read, as a fraction of the reference diagonal")
      ->check(CLI::Range(0.001, 0.2))
      ->capture_default_str();
  cmd->callback([a, &registry] { registry.exit_code = run_eval(*a); });
}

}  // namespace fire::cli
