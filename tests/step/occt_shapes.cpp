#include "occt_shapes.hpp"

#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepAlgoAPI_Cut.hxx>
#include <BRepFilletAPI_MakeFillet.hxx>
#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepPrimAPI_MakeCylinder.hxx>
#include <BRepPrimAPI_MakePrism.hxx>
#include <BRepPrimAPI_MakeRevol.hxx>
#include <BRepPrimAPI_MakeSphere.hxx>
#include <BRepPrimAPI_MakeTorus.hxx>
#include <BRepOffsetAPI_ThruSections.hxx>
#include <BRepBuilderAPI_MakeEdge.hxx>
#include <BRepBuilderAPI_MakeWire.hxx>
#include <GC_MakeArcOfCircle.hxx>
#include <IGESControl_Writer.hxx>
#include <STEPCAFControl_Writer.hxx>
#include <STEPControl_Writer.hxx>
#include <TDataStd_Name.hxx>
#include <TDocStd_Document.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <XCAFApp_Application.hxx>
#include <XCAFDoc_DocumentTool.hxx>
#include <XCAFDoc_ShapeTool.hxx>
#include <gp_Pln.hxx>

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <vector>

namespace lamina::step_testing {

TopoDS_Shape filleted_box(double x, double y, double z, double fillet) {
  const TopoDS_Shape box = BRepPrimAPI_MakeBox(x, y, z).Shape();
  BRepFilletAPI_MakeFillet round(box);
  for (TopExp_Explorer e(box, TopAbs_EDGE); e.More(); e.Next()) round.Add(fillet, TopoDS::Edge(e.Current()));
  return round.Shape();
}

TopoDS_Shape tube(double outer_r, double inner_r, double height) {
  const TopoDS_Shape outer = BRepPrimAPI_MakeCylinder(outer_r, height).Shape();
  const TopoDS_Shape inner = BRepPrimAPI_MakeCylinder(inner_r, height).Shape();
  return BRepAlgoAPI_Cut(outer, inner).Shape();
}

TopoDS_Shape box(double x, double y, double z) { return BRepPrimAPI_MakeBox(x, y, z).Shape(); }

TopoDS_Shape sphere(double r) { return BRepPrimAPI_MakeSphere(r).Shape(); }

TopoDS_Shape torus(double major_r, double minor_r) { return BRepPrimAPI_MakeTorus(major_r, minor_r).Shape(); }

// A loft between two arcs of different sagitta (a B-spline face), extruded down 10 mm.
TopoDS_Shape bspline_solid() {
  auto wire_of = [](double z, double sag) {
    const Handle(Geom_TrimmedCurve) arc = GC_MakeArcOfCircle(gp_Pnt(0, 0, z), gp_Pnt(10, sag, z), gp_Pnt(20, 0, z)).Value();
    const TopoDS_Edge arc_edge = BRepBuilderAPI_MakeEdge(arc);
    const TopoDS_Edge chord = BRepBuilderAPI_MakeEdge(gp_Pnt(20, 0, z), gp_Pnt(0, 0, z));
    return BRepBuilderAPI_MakeWire(arc_edge, chord).Wire();
  };
  BRepOffsetAPI_ThruSections loft(Standard_True, Standard_False);
  loft.AddWire(wire_of(0, 4));
  loft.AddWire(wire_of(15, 8));
  loft.Build();
  return loft.Shape();
}

namespace {

// A point of the knob's profile: radius r on +X, height z.
gp_Pnt rz(double r, double z) { return gp_Pnt(r, 0, z); }
TopoDS_Edge line(const gp_Pnt& a, const gp_Pnt& b) { return BRepBuilderAPI_MakeEdge(a, b); }
TopoDS_Edge arc(const gp_Pnt& a, const gp_Pnt& mid, const gp_Pnt& b) {
  return BRepBuilderAPI_MakeEdge(GC_MakeArcOfCircle(a, mid, b).Value());
}

}  // namespace

// The numbers are knob.scad's (examples/README.md): flange Ø76 x 12 with six Ø6 holes on Ø62,
// the neck r(z) = 34 - sqrt(14² - (z-20)²) for z 12..28, the head Ø60 to z 32, an R6 round
// centred (24, 32) blending into an R60 dome centred on the axis, a Ø10 bore.
TopoDS_Shape knob() {
  const double neck_r = 34 - std::sqrt(14.0 * 14.0 - 8.0 * 8.0);         // 22.51 at z = 12 and 28
  const double dome_cz = 32 - std::sqrt(54.0 * 54.0 - 24.0 * 24.0);      // -16.37
  const double blend = std::atan2(32 - dome_cz, 24.0);                  // where the round meets the dome
  const double dome_end = std::acos(5.0 / 60.0);                        // where the dome meets the bore
  auto round_at = [](double a) { return rz(24 + 6 * std::cos(a), 32 + 6 * std::sin(a)); };
  auto dome_at = [&](double a) { return rz(60 * std::cos(a), dome_cz + 60 * std::sin(a)); };
  BRepBuilderAPI_MakeWire profile;
  profile.Add(line(rz(5, 0), rz(38, 0)));
  profile.Add(line(rz(38, 0), rz(38, 12)));
  profile.Add(line(rz(38, 12), rz(neck_r, 12)));
  profile.Add(arc(rz(neck_r, 12), rz(20, 20), rz(neck_r, 28)));
  profile.Add(line(rz(neck_r, 28), rz(30, 28)));
  profile.Add(line(rz(30, 28), rz(30, 32)));
  profile.Add(arc(rz(30, 32), round_at(blend / 2), round_at(blend)));
  profile.Add(arc(round_at(blend), dome_at((blend + dome_end) / 2), dome_at(dome_end)));
  profile.Add(line(dome_at(dome_end), rz(5, 0)));
  const TopoDS_Face section = BRepBuilderAPI_MakeFace(profile.Wire(), Standard_True);
  TopoDS_Shape part = BRepPrimAPI_MakeRevol(section, gp_Ax1(gp::Origin(), gp::DZ()), 2 * std::numbers::pi).Shape();
  for (int k = 0; k < 6; ++k) {
    const double a = (30 + 60 * k) * std::numbers::pi / 180;
    const gp_Ax2 at(gp_Pnt(31 * std::cos(a), 31 * std::sin(a), -1), gp::DZ());
    part = BRepAlgoAPI_Cut(part, BRepPrimAPI_MakeCylinder(at, 3, 14).Shape()).Shape();
  }
  return part;
}

TopoDS_Shape lone_face() { return BRepBuilderAPI_MakeFace(gp_Pln(gp::Origin(), gp::DZ()), 0, 10, 0, 10).Shape(); }

void write_cad(const TopoDS_Shape& shape, const std::filesystem::path& path) {
  if (path.extension() == ".igs" || path.extension() == ".iges") {
    IGESControl_Writer writer("MM", 1);
    writer.AddShape(shape);
    writer.ComputeModel();
    if (!writer.Write(path.c_str())) throw std::runtime_error("IGES write failed: " + path.string());
    return;
  }
  STEPControl_Writer writer;
  if (writer.Transfer(shape, STEPControl_AsIs) != IFSelect_RetDone || writer.Write(path.c_str()) != IFSelect_RetDone)
    throw std::runtime_error("STEP write failed: " + path.string());
}

void write_assembly(const TopoDS_Shape& part, double dx, const std::filesystem::path& path) {
  Handle(TDocStd_Document) doc;
  XCAFApp_Application::GetApplication()->NewDocument("MDTV-XCAF", doc);
  const Handle(XCAFDoc_ShapeTool) tool = XCAFDoc_DocumentTool::ShapeTool(doc->Main());
  const TDF_Label assembly = tool->NewShape();
  TDataStd_Name::Set(assembly, "bracket");
  const TDF_Label part_label = tool->AddShape(part, Standard_False);
  TDataStd_Name::Set(part_label, "bolt");
  gp_Trsf moved;
  moved.SetTranslation(gp_Vec(dx, 0, 0));
  TDataStd_Name::Set(tool->AddComponent(assembly, part_label, TopLoc_Location()), "bolt 1");
  TDataStd_Name::Set(tool->AddComponent(assembly, part_label, TopLoc_Location(moved)), "bolt 2");
  tool->UpdateAssemblies();
  STEPCAFControl_Writer writer;
  if (!writer.Transfer(doc, STEPControl_AsIs) || writer.Write(path.c_str()) != IFSelect_RetDone)
    throw std::runtime_error("STEP assembly write failed: " + path.string());
  XCAFApp_Application::GetApplication()->Close(doc);
}

void write_named_step(const TopoDS_Shape& shape, const std::string& name, const std::filesystem::path& path) {
  Handle(TDocStd_Document) doc;
  XCAFApp_Application::GetApplication()->NewDocument("MDTV-XCAF", doc);
  const Handle(XCAFDoc_ShapeTool) tool = XCAFDoc_DocumentTool::ShapeTool(doc->Main());
  TDataStd_Name::Set(tool->AddShape(shape, Standard_False), name.c_str());
  STEPCAFControl_Writer writer;
  if (!writer.Transfer(doc, STEPControl_AsIs) || writer.Write(path.c_str()) != IFSelect_RetDone)
    throw std::runtime_error("STEP write failed: " + path.string());
  XCAFApp_Application::GetApplication()->Close(doc);
}

void write_assembly_of(const std::vector<PlacedPart>& parts, const std::filesystem::path& path) {
  Handle(TDocStd_Document) doc;
  XCAFApp_Application::GetApplication()->NewDocument("MDTV-XCAF", doc);
  const Handle(XCAFDoc_ShapeTool) tool = XCAFDoc_DocumentTool::ShapeTool(doc->Main());
  const TDF_Label assembly = tool->NewShape();
  TDataStd_Name::Set(assembly, "assembly");
  for (const PlacedPart& p : parts) {
    const TDF_Label label = tool->AddShape(p.shape, Standard_False);
    TDataStd_Name::Set(label, p.name.c_str());
    gp_Trsf moved;
    moved.SetTranslation(gp_Vec(p.dx, p.dy, p.dz));
    TDataStd_Name::Set(tool->AddComponent(assembly, label, TopLoc_Location(moved)), (p.name + " 1").c_str());
  }
  tool->UpdateAssemblies();
  STEPCAFControl_Writer writer;
  if (!writer.Transfer(doc, STEPControl_AsIs) || writer.Write(path.c_str()) != IFSelect_RetDone)
    throw std::runtime_error("STEP assembly write failed: " + path.string());
  XCAFApp_Application::GetApplication()->Close(doc);
}

}  // namespace lamina::step_testing
