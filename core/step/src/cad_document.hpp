#pragma once
// A STEP or IGES file as solids placed in the file's frame (mm), with the names its products and
// assembly components give them.
#include "lamina/core/error.hpp"
#include "lamina/step/cad_reader.hpp"
#include "occt_session.hpp"

#include <TopoDS_Shape.hxx>

#include <expected>
#include <string>
#include <vector>

namespace lamina::step_detail {

struct LocatedSolid {
  TopoDS_Shape shape;  // a TopoDS_Solid, its assembly placement applied
  std::string name;    // component path, "/"-separated ("bracket/bolt 2"); may be empty
};

struct CadDocument {
  std::string format;  // "step" | "iges"
  std::vector<LocatedSolid> solids;
  std::size_t faces_outside_solids = 0;  // faces in no solid (surface models)
  std::string length_unit;               // as the file names it
};

std::expected<CadDocument, Error> read_cad_document(const std::filesystem::path& path, const std::string& name,
                                                    const CadReadOptions& options, Deadline& deadline);

}  // namespace lamina::step_detail
