// The CAD export measured: networks reconstructed to a cage (reconstruct_cage), the cage's limit surface as
// B-spline patches (systems/catmull_clark/bspline_patches.hpp), written as STEP and IGES (platform/cad) and read
// back with OpenCASCADE. Per network: its size, the cage's, the patches (exact, fitted, fit level, largest fit
// error), the time of each step, each file's size and what OpenCASCADE reads from it.
//
//   bench_cad [--out DIR] [--mesh NAME ...] [--network FILE.fnet ...]
//     --mesh NAME     the network of every second edge loop of a bundled mesh (meshes/NAME.obj), as the tests
//                     make them (default: pawn, rook, egg)
//     --network FILE  a network file (fire replay -o, fire network-from-mesh -o)
//     --out DIR       keep the files there as NAME.step and NAME.igs (default: a temporary folder, removed)
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "platform/cad/cad_export.hpp"
#include "platform/files.hpp"
#include "platform/network_file.hpp"
#include "platform/obj.hpp"
#include "systems/reconstruct/reconstruct.hpp"
#include "systems/catmull_clark/bspline_patches.hpp"
#include "systems/synth/network_from_mesh.hpp"

using namespace fire;

namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

Result<Mesh> mesh_network(const std::string& name) {
  Result<std::string> path = bundled_data_file("meshes/" + name + ".obj");
  if (!path) return Result<Mesh>::failure(path.error());
  Result<PolygonMesh> mesh = read_obj(*path);
  if (!mesh) return Result<Mesh>::failure(mesh.error());
  return network_from_mesh(mesh->view(name), UnrefineOptions{.unrefine = 2, .limit = true});
}

int measure(const std::string& name, const Mesh& net, const std::string& out) {
  reconstruct::Options options;
  options.levels = 2;
  Clock::time_point start = Clock::now();
  Result<Cage> cage = reconstruct::reconstruct_cage(net, options);
  if (!cage) {
    std::fprintf(stderr, "bench_cad: %s: %s\n", name.c_str(), cage.error().c_str());
    return 1;
  }
  const double reconstruct_ms = ms_since(start);
  start = Clock::now();
  Result<catmull_clark::BsplineConversion> c = catmull_clark::bspline_patches(*cage);
  if (!c) {
    std::fprintf(stderr, "bench_cad: %s: %s\n", name.c_str(), c.error().c_str());
    return 1;
  }
  const double convert_ms = ms_since(start);
  std::printf("%s: network %zu faces, cage %u faces; reconstruct %.0f ms; patches %zu (%u exact, %u fitted, "
              "deepest level %u), largest fit error %.2e of the diagonal; convert %.0f ms\n",
              name.c_str(), net.face_count(), cage->mesh.face_count(), reconstruct_ms, c->patches.patch_count(),
              c->exact, c->fitted, c->fit_level, c->max_fit_error, convert_ms);
  for (const char* ext : {".step", ".igs"}) {
    const std::string path = (std::filesystem::path(out) / (name + ext)).string();
    start = Clock::now();
    Result<cad::CadWritten> written = cad::write_cad(c->patches, path);
    if (!written) {
      std::fprintf(stderr, "bench_cad: %s\n", written.error().c_str());
      return 1;
    }
    const double write_ms = ms_since(start);
    start = Clock::now();
    Result<cad::CadShapeInfo> info = cad::read_cad(path);
    if (!info) {
      std::fprintf(stderr, "bench_cad: %s\n", info.error().c_str());
      return 1;
    }
    const double read_ms = ms_since(start);
    const Vec3 size = info->box_max - info->box_min;
    std::printf("  %-5s %6.2f MB  write %5.0f ms  read %5.0f ms: %s, %zu faces, %zu shells, %zu solids, %zu free "
                "edges, %.1f x %.1f x %.1f %s\n",
                ext + 1, double(std::filesystem::file_size(path)) / 1e6, write_ms, read_ms,
                info->valid ? "valid" : "NOT VALID", info->faces, info->shells, info->solids, info->free_edges,
                size.x(), size.y(), size.z(), info->unit.c_str());
    if (!info->valid || info->faces != c->patches.patch_count()) return 1;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> meshes, networks;
  std::string out;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--mesh" && i + 1 < argc) {
      meshes.push_back(argv[++i]);
    } else if (arg == "--network" && i + 1 < argc) {
      networks.push_back(argv[++i]);
    } else if (arg == "--out" && i + 1 < argc) {
      out = argv[++i];
    } else {
      std::fprintf(stderr, "usage: bench_cad [--out DIR] [--mesh NAME ...] [--network FILE.fnet ...]\n");
      return 2;
    }
  }
  if (!cad::cad_available()) {
    std::fprintf(stderr, "bench_cad: FIRE was built without OpenCASCADE\n");
    return 1;
  }
  if (meshes.empty() && networks.empty()) meshes = {"pawn", "rook", "egg"};
  const bool temporary = out.empty();
  if (temporary) {
    std::string pattern = (std::filesystem::temp_directory_path() / "fire-bench-cad-XXXXXX").string();
    if (!::mkdtemp(pattern.data())) {
      std::perror("bench_cad: mkdtemp");
      return 1;
    }
    out = pattern;
  } else if (Status s = make_directory(out); !s) {
    std::fprintf(stderr, "bench_cad: %s\n", s.error.c_str());
    return 1;
  }
  int status = 0;
  for (const std::string& name : meshes) {
    Result<Mesh> net = mesh_network(name);
    if (!net) {
      std::fprintf(stderr, "bench_cad: %s\n", net.error().c_str());
      status = 1;
      continue;
    }
    status |= measure(name, *net, out);
  }
  for (const std::string& file : networks) {
    Result<Mesh> net = load_network(file);
    if (!net) {
      std::fprintf(stderr, "bench_cad: %s\n", net.error().c_str());
      status = 1;
      continue;
    }
    status |= measure(std::filesystem::path(file).stem().string(), *net, out);
  }
  if (temporary) std::filesystem::remove_all(out);
  return status;
}
