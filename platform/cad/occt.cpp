// STEP and IGES through OpenCASCADE (see cad_export.hpp).
#include <BRepBndLib.hxx>
#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepBuilderAPI_Sewing.hxx>
#include <BRepCheck_Analyzer.hxx>
#include <BRepTools.hxx>
#include <BRep_Builder.hxx>
#include <BRep_Tool.hxx>
#include <Bnd_Box.hxx>
#include <Geom_BSplineSurface.hxx>
#include <Geom_Curve.hxx>
#include <IGESControl_Controller.hxx>
#include <IGESControl_Reader.hxx>
#include <IGESControl_Writer.hxx>
#include <IGESData_IGESModel.hxx>
#include <Interface_Static.hxx>
#include <Message.hxx>
#include <Message_Messenger.hxx>
#include <Message_PrinterOStream.hxx>
#include <Precision.hxx>
#include <STEPControl_Controller.hxx>
#include <STEPControl_Reader.hxx>
#include <STEPControl_Writer.hxx>
#include <ShapeFix_Solid.hxx>
#include <Standard_Failure.hxx>
#include <TColStd_Array1OfInteger.hxx>
#include <TColStd_Array1OfReal.hxx>
#include <TColStd_SequenceOfAsciiString.hxx>
#include <TColgp_Array2OfPnt.hxx>
#include <TopExp.hxx>
#include <TopExp_Explorer.hxx>
#include <TopTools_IndexedDataMapOfShapeListOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Compound.hxx>
#include <TopoDS_Edge.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Shell.hxx>
#include <TopoDS_Solid.hxx>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <mutex>
#include <optional>
#include <sstream>

#include <fcntl.h>
#include <unistd.h>

#include "platform/cad/cad_export.hpp"
#include "platform/files.hpp"

namespace fire::cad {
namespace {

// OpenCASCADE's translators are configured through process-wide statics (units, schema, modes) and print to
// stdout by default: one lock around every use, and its printers removed once.
std::mutex& occt_lock() {
  static std::mutex lock;
  return lock;
}
void initialize_occt() {
  static std::once_flag once;
  std::call_once(once, [] {
    Message::DefaultMessenger()->RemovePrinters(STANDARD_TYPE(Message_PrinterOStream));
    STEPControl_Controller::Init();
    IGESControl_Controller::Init();
  });
}

// OpenCASCADE's names of the units (STEP, IGES and its own "cascade" unit take the same).
const char* occt_unit(LengthUnit unit) {
  switch (unit) {
    case LengthUnit::Millimetre: return "MM";
    case LengthUnit::Centimetre: return "CM";
    case LengthUnit::Metre: return "M";
  }
  return "MM";
}

// Edges of exactly one face, degenerate ones left out.
std::vector<TopoDS_Edge> free_edges(const TopoDS_Shape& shape) {
  TopTools_IndexedDataMapOfShapeListOfShape faces_of_edge;
  TopExp::MapShapesAndUniqueAncestors(shape, TopAbs_EDGE, TopAbs_FACE, faces_of_edge);
  std::vector<TopoDS_Edge> edges;
  for (int i = 1; i <= faces_of_edge.Extent(); ++i) {
    const TopoDS_Edge& edge = TopoDS::Edge(faces_of_edge.FindKey(i));
    if (faces_of_edge.FindFromIndex(i).Extent() == 1 && !BRep_Tool::Degenerated(edge)) edges.push_back(edge);
  }
  return edges;
}
size_t free_edge_count(const TopoDS_Shape& shape) { return free_edges(shape).size(); }

size_t count_of(const TopoDS_Shape& shape, TopAbs_ShapeEnum kind) {
  size_t n = 0;
  for (TopExp_Explorer ex(shape, kind); ex.More(); ex.Next()) ++n;
  return n;
}

struct Built {
  TopoDS_Shape shape;
  CadWritten written;
};

// The patches as faces sewn into shells, each closed shell a solid; `scale` from metres to the file's unit.
Result<Built> build_shape(const BsplinePatches& patches, double scale, const std::string& path) {
  using R = Result<Built>;
  const size_t n = patches.patch_count();
  if (n == 0) return R::failure(path + ": no patches to write");
  std::vector<Vec3> points(patches.controls.size());
  for (size_t i = 0; i < points.size(); ++i) points[i] = scale * patches.controls[i];
  // The patches share their sides exactly or, across a T-junction, along the same cubic to rounding: a
  // tolerance far below any patch's size and far above rounding joins them all.
  Built built;
  built.written.sewing_tolerance = 1e-7 * bounding_box_diagonal(points);
  BRepBuilderAPI_Sewing sewing(built.written.sewing_tolerance);
  TColStd_Array1OfReal knots(1, 2);
  knots(1) = 0.0, knots(2) = 1.0;
  TColStd_Array1OfInteger multiplicities(1, 2);
  multiplicities(1) = multiplicities(2) = 4;
  for (size_t p = 0; p < n; ++p) {
    TColgp_Array2OfPnt poles(1, 4, 1, 4);
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 4; ++i) {
        const Vec3& c = points[16 * p + 4 * size_t(j) + size_t(i)];
        if (!is_finite(c)) return R::failure(path + ": patch " + std::to_string(p) + " has a control point that is not finite");
        poles(i + 1, j + 1) = gp_Pnt(c.x(), c.y(), c.z());
      }
    Handle(Geom_BSplineSurface) surface =
        new Geom_BSplineSurface(poles, knots, knots, multiplicities, multiplicities, 3, 3);
    BRepBuilderAPI_MakeFace face(surface, Precision::Confusion());
    if (!face.IsDone()) return R::failure(path + ": OpenCASCADE cannot make a face of patch " + std::to_string(p));
    sewing.Add(face.Face());
  }
  sewing.Perform();
  const TopoDS_Shape sewn = sewing.SewedShape();
  BRep_Builder builder;
  TopoDS_Compound parts;
  builder.MakeCompound(parts);
  size_t part_count = 0;
  TopoDS_Shape last;
  ShapeFix_Solid fix;
  for (TopExp_Explorer ex(sewn, TopAbs_SHELL); ex.More(); ex.Next()) {
    const TopoDS_Shell& shell = TopoDS::Shell(ex.Current());
    if (free_edge_count(shell) == 0) {
      // Oriented so that the solid is the inside (ShapeFix_Solid turns the shell if it faces inwards).
      last = fix.SolidFromShell(shell);
      ++built.written.solids;
    } else {
      last = shell;
      ++built.written.shells;
    }
    builder.Add(parts, last);
    ++part_count;
  }
  // A patch that nothing was sewn to stays a face of its own.
  for (TopExp_Explorer ex(sewn, TopAbs_FACE, TopAbs_SHELL); ex.More(); ex.Next()) {
    last = ex.Current();
    builder.Add(parts, last);
    ++part_count;
  }
  built.shape = part_count == 1 ? last : TopoDS_Shape(parts);
  built.written.faces = count_of(built.shape, TopAbs_FACE);
  built.written.free_edges = free_edge_count(built.shape);
  if (built.written.faces != n)
    return R::failure(path + ": sewing left " + std::to_string(built.written.faces) + " faces of " + std::to_string(n) +
                      " patches");
  return built;
}

// `path` + a temporary suffix, created here so that an unwritable folder is reported with its reason.
Result<std::string> temporary_beside(const std::string& path) {
  const std::string tmp = path + ".tmp." + std::to_string(::getpid());
  FILE* f = std::fopen(tmp.c_str(), "wb");
  if (!f) return Result<std::string>::failure(path + ": cannot write (" + std::strerror(errno) + ")");
  std::fclose(f);
  return tmp;
}

// The written temporary file made durable and moved to `path`.
Status move_into_place(const std::string& tmp, const std::string& path) {
  const int fd = ::open(tmp.c_str(), O_RDONLY | O_CLOEXEC);
  const bool synced = fd >= 0 && ::fsync(fd) == 0;
  const int err = errno;
  if (fd >= 0) ::close(fd);
  if (!synced) {
    std::remove(tmp.c_str());
    return Status::failure(path + ": write failed (" + std::strerror(err) + ")");
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    const int rename_err = errno;
    std::remove(tmp.c_str());
    return Status::failure(path + ": cannot replace (" + std::strerror(rename_err) + ")");
  }
  return Status::success();
}

Status write_step(const TopoDS_Shape& shape, const std::string& path, LengthUnit unit) {
  Interface_Static::SetCVal("write.step.unit", occt_unit(unit));
  Interface_Static::SetCVal("write.step.schema", "AP214IS");
  STEPControl_Writer writer;
  if (writer.Transfer(shape, STEPControl_AsIs) != IFSelect_RetDone)
    return Status::failure(path + ": OpenCASCADE could not translate the shape to STEP");
  Result<std::string> tmp = temporary_beside(path);
  if (!tmp) return Status::failure(tmp.error());
  if (writer.Write(tmp->c_str()) != IFSelect_RetDone) {
    std::remove(tmp->c_str());
    return Status::failure(path + ": OpenCASCADE could not write the STEP file");
  }
  return move_into_place(*tmp, path);
}

Status write_iges(const TopoDS_Shape& shape, const std::string& path, LengthUnit unit) {
  Interface_Static::SetCVal("write.iges.unit", occt_unit(unit));
  Interface_Static::SetIVal("write.iges.brep.mode", 1);
  IGESControl_Writer writer(occt_unit(unit), 1);  // BRep mode: faces in shells and solids, not loose surfaces
  if (!writer.AddShape(shape)) return Status::failure(path + ": OpenCASCADE could not translate the shape to IGES");
  writer.ComputeModel();
  std::ostringstream out;
  if (!writer.Write(out)) return Status::failure(path + ": OpenCASCADE could not write the IGES data");
  return write_file_atomic(path, out.str());
}

// A length unit as the files name it: ours for it, and millimetres per unit.
std::optional<std::pair<std::string, double>> known_unit(std::string name) {
  std::transform(name.begin(), name.end(), name.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  if (name == "mm" || name == "millimetre" || name == "millimeter") return std::pair<std::string, double>{"mm", 1.0};
  if (name == "cm" || name == "centimetre" || name == "centimeter") return std::pair<std::string, double>{"cm", 10.0};
  if (name == "m" || name == "metre" || name == "meter") return std::pair<std::string, double>{"m", 1000.0};
  if (name == "in" || name == "inch") return std::pair<std::string, double>{"in", 25.4};
  return std::nullopt;
}

}  // namespace

bool cad_available() { return true; }

Result<CadWritten> write_cad(const BsplinePatches& patches, const std::string& path, LengthUnit unit) {
  Result<CadFormat> format = cad_format_of(path);
  if (!format) return Result<CadWritten>::failure(format.error());
  if (is_directory(path)) return Result<CadWritten>::failure(path + ": is a folder, not a file");
  std::lock_guard<std::mutex> guard(occt_lock());
  initialize_occt();
  try {
    // The shape in millimetres, OpenCASCADE's own unit, which its writers convert to the file's.
    Interface_Static::SetCVal("xstep.cascade.unit", "MM");
    Result<Built> built = build_shape(patches, units_per_metre(LengthUnit::Millimetre), path);
    if (!built) return Result<CadWritten>::failure(built.error());
    built->written.sewing_tolerance *= units_per_metre(unit) / units_per_metre(LengthUnit::Millimetre);
    const Status s = *format == CadFormat::Step ? write_step(built->shape, path, unit)
                                                : write_iges(built->shape, path, unit);
    if (!s) return Result<CadWritten>::failure(s.error);
    return built->written;
  } catch (const Standard_Failure& e) {
    return Result<CadWritten>::failure(path + ": OpenCASCADE failed: " + e.GetMessageString());
  }
}

Result<CadShapeInfo> read_cad(const std::string& path, uint32_t samples_per_side) {
  using R = Result<CadShapeInfo>;
  Result<CadFormat> format = cad_format_of(path);
  if (!format) return R::failure(format.error());
  if (is_directory(path)) return R::failure(path + ": is a folder, not a file");
  if (FILE* f = std::fopen(path.c_str(), "rb")) std::fclose(f);
  else return R::failure(path + ": cannot open (" + std::strerror(errno) + ")");
  std::lock_guard<std::mutex> guard(occt_lock());
  initialize_occt();
  try {
    CadShapeInfo info;
    TopoDS_Shape shape;
    // Shapes come out in OpenCASCADE's own unit, set to millimetres here, and are scaled to the file's.
    Interface_Static::SetCVal("xstep.cascade.unit", "MM");
    std::string file_unit;
    if (*format == CadFormat::Step) {
      STEPControl_Reader reader;
      if (reader.ReadFile(path.c_str()) != IFSelect_RetDone) return R::failure(path + ": not a STEP file OpenCASCADE can read");
      TColStd_SequenceOfAsciiString lengths, angles, solid_angles;
      reader.FileUnits(lengths, angles, solid_angles);
      if (lengths.IsEmpty()) return R::failure(path + ": the STEP file states no length unit");
      file_unit = lengths.First().ToCString();
      reader.TransferRoots();
      shape = reader.OneShape();
    } else {
      IGESControl_Reader reader;
      if (reader.ReadFile(path.c_str()) != IFSelect_RetDone) return R::failure(path + ": not an IGES file OpenCASCADE can read");
      file_unit = reader.IGESModel()->GlobalSection().UnitName()->ToCString();
      reader.TransferRoots();
      shape = reader.OneShape();
    }
    const std::optional<std::pair<std::string, double>> unit = known_unit(file_unit);
    if (!unit) return R::failure(path + ": its length unit '" + file_unit + "' is not one this reader knows");
    info.unit = unit->first;
    const double scale = 1.0 / unit->second;
    if (shape.IsNull()) return R::failure(path + ": OpenCASCADE read no shape from it");
    info.valid = BRepCheck_Analyzer(shape).IsValid();
    info.faces = count_of(shape, TopAbs_FACE);
    info.shells = count_of(shape, TopAbs_SHELL);
    info.solids = count_of(shape, TopAbs_SOLID);
    for (const TopoDS_Edge& edge : free_edges(shape)) {
      double first, last;
      const Handle(Geom_Curve) curve = BRep_Tool::Curve(edge, first, last);
      if (curve.IsNull()) continue;
      const gp_Pnt middle = curve->Value(0.5 * (first + last));
      info.free_edge_middles.push_back(scale * Vec3(middle.X(), middle.Y(), middle.Z()));
    }
    info.free_edges = free_edges(shape).size();
    // Around the surfaces' control points: exact and fast (AddOptimal's search for the surfaces' extremes
    // took most of the time of reading the rook).
    Bnd_Box box;
    BRepBndLib::Add(shape, box, false);
    if (!box.IsVoid()) {
      box.SetGap(0.0);
      double x0, y0, z0, x1, y1, z1;
      box.Get(x0, y0, z0, x1, y1, z1);
      info.box_min = scale * Vec3(x0, y0, z0);
      info.box_max = scale * Vec3(x1, y1, z1);
    }
    if (samples_per_side > 1) {
      for (TopExp_Explorer ex(shape, TopAbs_FACE); ex.More(); ex.Next()) {
        const TopoDS_Face& face = TopoDS::Face(ex.Current());
        const Handle(Geom_Surface) surface = BRep_Tool::Surface(face);
        double u0, u1, v0, v1;
        BRepTools::UVBounds(face, u0, u1, v0, v1);
        for (uint32_t j = 0; j < samples_per_side; ++j)
          for (uint32_t i = 0; i < samples_per_side; ++i) {
            const double s = double(i) / (samples_per_side - 1), t = double(j) / (samples_per_side - 1);
            const gp_Pnt p = surface->Value(u0 + s * (u1 - u0), v0 + t * (v1 - v0));
            info.samples.push_back(scale * Vec3(p.X(), p.Y(), p.Z()));
          }
      }
    }
    return info;
  } catch (const Standard_Failure& e) {
    return R::failure(path + ": OpenCASCADE failed: " + e.GetMessageString());
  }
}

}  // namespace fire::cad
