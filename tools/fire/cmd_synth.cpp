// fire network-from-mesh: synthetic curve networks from OBJ control meshes (thesis chapter 7).
#include <iostream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>

#include "platform/network_file.hpp"
#include "platform/obj.hpp"
#include "systems/synth/network_from_mesh.hpp"
#include "tools/fire/commands.hpp"

namespace fire::cli {

namespace {

struct SynthArgs {
  std::string mesh_path, out_path;
  UnrefineOptions options;
};

int run_network_from_mesh(const SynthArgs& a) {
  auto polygons = read_obj(a.mesh_path);
  if (!polygons) {
    std::cerr << "fire network-from-mesh: " << polygons.error() << "\n";
    return 1;
  }
  auto net = network_from_mesh(polygons->view(a.mesh_path), a.options);
  if (!net) {
    std::cerr << "fire network-from-mesh: " << net.error() << "\n";
    return 1;
  }
  const Mesh& m = *net;
  if (auto s = save_network(m, a.out_path); !s) {
    std::cerr << "fire network-from-mesh: " << s.error << "\n";
    return 1;
  }
  std::map<uint32_t, size_t> sizes;  // numeric order, not the string order of JSON keys
  for (FaceIndex f{0}; f < m.face_slots(); ++f)
    if (m.face_alive(f)) ++sizes[m.faces.edge_count[f]];
  nlohmann::ordered_json out;
  out["vertices"] = m.vertex_count();
  out["edges"] = m.edge_count();
  out["faces"] = m.face_count();
  out["points"] = m.live_point_count();
  out["face_sizes"] = nlohmann::ordered_json::object();
  for (auto [size, count] : sizes) out["face_sizes"][std::to_string(size)] = count;
  std::cout << out.dump() << "\n";
  return 0;
}

}  // namespace

void add_synth_commands(CLI::App& app, Registry& registry) {
  auto a = std::make_shared<SynthArgs>();
  CLI::App* cmd = app.add_subcommand("network-from-mesh",
                                     "Build a synthetic curve network from a manifold OBJ control mesh (thesis chapter 7)");
  cmd->footer(
      "Keeps every K-th edge loop (the border always), makes each chain of kept edges one polyline edge sampled "
      "linearly on the control edges (or on the limit surface, --limit), collapses interior vertices of valence 2 (keeping one where a face would have fewer than 3 sides) and adds seeded Gaussian noise. "
      "Prints one JSON line: vertices, edges, faces, points and the number of faces of each size.");
  cmd->add_option("MESH", a->mesh_path, "control mesh, OBJ (v and f lines); must be manifold and consistently oriented")
      ->required();
  cmd->add_option("--unrefine", a->options.unrefine, "K: keep every K-th edge loop (1 keeps every edge)")
      ->check(CLI::Range(1u, 1u << 20))
      ->capture_default_str();
  cmd->add_option("--noise", a->options.noise_percent,
                  "P: Gaussian noise with a standard deviation of P percent of the mean control-mesh edge length, "
                  "added to the interior polyline points (network vertices stay put)")
      ->check(kNonNegative)
      ->capture_default_str();
  cmd->add_option("--noise-correlation", a->options.noise_correlation_percent,
                  "L: make the noise correlated along each polyline, as a tracked and filtered pen's error is: a "
                  "Gaussian-weighted mean over arc length L percent of the mean control-mesh edge length, rescaled "
                  "so each point keeps the standard deviation of --noise (0: independent per point)")
      ->check(kNonNegative)
      ->capture_default_str();
  cmd->add_option("--seed", a->options.seed, "S: seed of the noise (same seed, same network on every run)")
      ->capture_default_str();
  cmd->add_option("--samples", a->options.samples_per_edge,
                  "polyline points per control-mesh edge (at least 8), placed linearly along it")
      ->check(CLI::Range(kMinSamplesPerEdge, 65536u))
      ->capture_default_str();
  cmd->add_flag("--limit", a->options.limit,
               "sample the control mesh's Catmull-Clark limit surface instead of its straight edges: vertices at their "
               "limit positions, each control edge sampled at the limit positions of its vertices after L subdivision "
               "levels (2^L >= --samples), so the network lies exactly on the limit surface");
  cmd->add_option("-o,--output", a->out_path, "curve network file to write (format: engine/NETWORK_FORMAT.md)")
      ->required();
  cmd->callback([a, &registry] { registry.exit_code = run_network_from_mesh(*a); });
}

}  // namespace fire::cli
