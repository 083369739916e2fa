#include "lamina/core/model_index.hpp"

#include "geometry/closest_point.hpp"

namespace lamina {

ModelDistanceIndex::ModelDistanceIndex(const Mesh& mesh, bool parallel)
    : mesh_(&mesh),
      faces_(mesh.faces.size()),
      tree_(std::make_unique<geometry_detail::TriangleTree>(mesh.vertices, mesh.faces,
                                                            geometry_detail::threads_for(parallel))) {}

ModelDistanceIndex::~ModelDistanceIndex() = default;

}  // namespace lamina
