#pragma once
// The model's triangles in a tree for distance queries, built once by whoever runs a whole plan
// and handed to the stages that measure against the model: the layering's verification and the
// deviation. Each built its own before: 0.21 s and about 100 MB on the 1M-triangle sphere, twice
// (issue 22). A stage given an index of another mesh (the deviation's reference of a STEP plan)
// builds its own, as without one.
#include "lamina/core/mesh.hpp"

#include <cstddef>
#include <memory>

namespace lamina {

namespace geometry_detail {
class TriangleTree;
}

class ModelDistanceIndex {
 public:
  ModelDistanceIndex(const Mesh& mesh, bool parallel);
  ~ModelDistanceIndex();
  ModelDistanceIndex(const ModelDistanceIndex&) = delete;
  ModelDistanceIndex& operator=(const ModelDistanceIndex&) = delete;

  // Built from this very mesh (the same object, as many facets as then).
  bool indexes(const Mesh& mesh) const { return &mesh == mesh_ && mesh.faces.size() == faces_; }
  const geometry_detail::TriangleTree& tree() const { return *tree_; }

 private:
  const Mesh* mesh_;
  std::size_t faces_;
  std::unique_ptr<geometry_detail::TriangleTree> tree_;
};

}  // namespace lamina
