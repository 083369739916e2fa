#pragma once
// Test parts made with OpenCASCADE, so the exact answers are known: written to STEP (or IGES)
// files the reader then reads as a customer's file.
#include <TopoDS_Shape.hxx>

#include <filesystem>
#include <string>
#include <vector>

namespace lamina::step_testing {

TopoDS_Shape filleted_box(double x, double y, double z, double fillet);  // 6 + 12 + 8 = 26 faces
TopoDS_Shape tube(double outer_r, double inner_r, double height);       // 4 faces: 2 cylinders, 2 planes
TopoDS_Shape sphere(double r);
TopoDS_Shape torus(double major_r, double minor_r);
TopoDS_Shape bspline_solid();  // a box whose top is a B-spline surface (a prism of a lofted face)
TopoDS_Shape lone_face();      // a planar face, no solid
TopoDS_Shape box(double x, double y, double z);
// examples/knob.scad's knob as an exact B-rep: the profile revolved (planes, cylinders, a concave
// torus for the neck, a torus for the round, a sphere for the dome), less six bolt holes.
TopoDS_Shape knob();

// Writes `shape` as STEP (AP214, mm) or IGES by the extension of `path`; throws on failure.
void write_cad(const TopoDS_Shape& shape, const std::filesystem::path& path);
// One solid as a named product (the name a CAD user gave the part), STEP AP214, mm.
void write_named_step(const TopoDS_Shape& shape, const std::string& name, const std::filesystem::path& path);
// Two solids as an assembly: `part` placed twice, the second moved by (dx, 0, 0), named.
void write_assembly(const TopoDS_Shape& part, double dx, const std::filesystem::path& path);

// An assembly of distinct parts (each its own product, named), each moved by its offset (mm).
struct PlacedPart {
  std::string name;
  TopoDS_Shape shape;
  double dx = 0, dy = 0, dz = 0;
};
void write_assembly_of(const std::vector<PlacedPart>& parts, const std::filesystem::path& path);

}  // namespace lamina::step_testing
