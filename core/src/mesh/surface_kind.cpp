#include "lamina/core/brep_surfaces.hpp"

namespace lamina {

const char* surface_kind_name(SurfaceKind kind) {
  switch (kind) {
    case SurfaceKind::plane: return "plane";
    case SurfaceKind::cylinder: return "cylinder";
    case SurfaceKind::cone: return "cone";
    case SurfaceKind::sphere: return "sphere";
    case SurfaceKind::torus: return "torus";
    case SurfaceKind::bspline: return "bspline";
    case SurfaceKind::bezier: return "bezier";
    case SurfaceKind::revolution: return "revolution";
    case SurfaceKind::extrusion: return "extrusion";
    case SurfaceKind::offset: return "offset";
    case SurfaceKind::other: return "other";
  }
  return "other";
}

}  // namespace lamina
