// read_cad_document: the file checked at its edges (size, signature, ending) before OCCT parses
// it, then read with XCAF (names, assembly structure) and walked to its placed solids.
#include "cad_document.hpp"

#include "lamina/core/mesh_io.hpp"

#include <IFSelect_ReturnStatus.hxx>
#include <IGESCAFControl_Reader.hxx>
#include <IGESData_GlobalSection.hxx>
#include <IGESData_IGESModel.hxx>
#include <STEPCAFControl_Reader.hxx>
#include <STEPControl_Reader.hxx>
#include <Standard_Failure.hxx>
#include <TCollection_AsciiString.hxx>
#include <TCollection_HAsciiString.hxx>
#include <TColStd_SequenceOfAsciiString.hxx>
#include <TDF_Label.hxx>
#include <TDF_LabelSequence.hxx>
#include <TDataStd_Name.hxx>
#include <TDocStd_Document.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <XCAFApp_Application.hxx>
#include <XCAFDoc_DocumentTool.hxx>
#include <XCAFDoc_ShapeTool.hxx>

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <fstream>
#include <string_view>

namespace lamina::step_detail {
namespace {

Error error(ErrorCode code, std::string message) { return Error{code, std::move(message)}; }

// The first and last bytes: a STEP file begins "ISO-10303-21;" and ends "END-ISO-10303-21;"; an
// IGES file's last record is its terminate section (a 'T' in column 73).
std::optional<Error> check_edges(const std::filesystem::path& path, const std::string& name, const std::string& format,
                                 const CadReadOptions& options) {
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  std::ifstream in(path, std::ios::binary);
  if (ec || !in) return error(ErrorCode::io_error, fmt::format("{}: cannot open", name));
  if (size > options.max_file_bytes)
    return error(ErrorCode::limit_exceeded, fmt::format("{}: {} bytes, above the {} byte limit for a CAD file", name,
                                                        size, options.max_file_bytes));
  std::string head(std::min<std::uintmax_t>(size, 256), '\0'), tail(std::min<std::uintmax_t>(size, 4096), '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  in.seekg(static_cast<std::streamoff>(size - tail.size()));
  in.read(tail.data(), static_cast<std::streamsize>(tail.size()));
  if (!in) return error(ErrorCode::io_error, fmt::format("{}: read failed", name));
  if (format == "step") {
    const auto first = head.find_first_not_of(" \t\r\n\xEF\xBB\xBF");
    if (first == std::string::npos || head.compare(first, 13, "ISO-10303-21;") != 0)
      return error(ErrorCode::unknown_format,
                   fmt::format("{}: not a STEP file: it does not begin with ISO-10303-21; (byte 0)", name));
    if (tail.find("END-ISO-10303-21;") == std::string::npos)
      return error(ErrorCode::truncated_file,
                   fmt::format("{}: the STEP file ends at byte {} without END-ISO-10303-21;: it was cut short", name, size));
    return std::nullopt;
  }
  while (!tail.empty() && (tail.back() == '\n' || tail.back() == '\r')) tail.pop_back();
  const auto line_start = tail.find_last_of('\n') == std::string::npos ? 0 : tail.find_last_of('\n') + 1;
  const std::string_view last(tail.data() + line_start, tail.size() - line_start);
  if (last.size() < 73 || last[72] != 'T')
    return error(ErrorCode::truncated_file,
                 fmt::format("{}: the IGES file's last record (byte {}) is not its terminate section: it was cut short "
                             "or is not IGES", name, size));
  return std::nullopt;
}

std::string label_name(const TDF_Label& label) {
  Handle(TDataStd_Name) attribute;
  if (!label.FindAttribute(TDataStd_Name::GetID(), attribute)) return {};
  return TCollection_AsciiString(attribute->Get()).ToCString();
}

// Every solid under `label`, its placement composed down the assembly tree.
void collect_solids(const TDF_Label& label, const TopLoc_Location& placement, const std::string& path,
                    CadDocument& doc) {
  if (XCAFDoc_ShapeTool::IsAssembly(label)) {
    TDF_LabelSequence components;
    XCAFDoc_ShapeTool::GetComponents(label, components);
    for (Standard_Integer i = 1; i <= components.Length(); ++i) {
      const TDF_Label& component = components.Value(i);
      TDF_Label referred;
      if (!XCAFDoc_ShapeTool::GetReferredShape(component, referred)) continue;
      std::string part = label_name(component);
      if (part.empty()) part = label_name(referred);
      collect_solids(referred, placement * XCAFDoc_ShapeTool::GetLocation(component), path.empty() ? part : path + "/" + part, doc);
    }
    return;
  }
  const TopoDS_Shape shape = XCAFDoc_ShapeTool::GetShape(label).Moved(placement);
  std::size_t in_solids = 0;
  for (TopExp_Explorer solid(shape, TopAbs_SOLID); solid.More(); solid.Next()) {
    doc.solids.push_back({solid.Current(), path});
    for (TopExp_Explorer face(solid.Current(), TopAbs_FACE); face.More(); face.Next()) ++in_solids;
  }
  std::size_t faces = 0;
  for (TopExp_Explorer face(shape, TopAbs_FACE); face.More(); face.Next()) ++faces;
  doc.faces_outside_solids += faces - std::min(faces, in_solids);
}

template <class Reader>
std::expected<CadDocument, Error> transfer(Reader& reader, const std::string& name, const std::string& format,
                                           Deadline& deadline) {
  reader.SetNameMode(true);
  reader.SetColorMode(false);
  reader.SetLayerMode(false);
  Handle(TDocStd_Document) doc;
  const Handle(XCAFApp_Application) app = XCAFApp_Application::GetApplication();
  app->NewDocument("MDTV-XCAF", doc);
  struct Closer {
    const Handle(XCAFApp_Application)& app;
    Handle(TDocStd_Document)& doc;
    ~Closer() { app->Close(doc); }
  } closer{app, doc};
  const bool transferred = reader.Transfer(doc, deadline.Start());
  if (deadline.passed())
    return std::unexpected(error(ErrorCode::limit_exceeded, fmt::format("{}: reading took longer than its limit", name)));
  if (!transferred)
    return std::unexpected(error(ErrorCode::parse_error, fmt::format("{}: the {} reader found nothing it could "
                                                                     "transfer into shapes", name, format)));
  CadDocument out;
  out.format = format;
  const Handle(XCAFDoc_ShapeTool) shapes = XCAFDoc_DocumentTool::ShapeTool(doc->Main());
  TDF_LabelSequence roots;
  shapes->GetFreeShapes(roots);
  for (Standard_Integer i = 1; i <= roots.Length(); ++i)
    collect_solids(roots.Value(i), TopLoc_Location(), label_name(roots.Value(i)), out);
  return out;
}

std::string step_length_unit(STEPCAFControl_Reader& reader) {
  TColStd_SequenceOfAsciiString lengths, angles, solid_angles;
  reader.ChangeReader().FileUnits(lengths, angles, solid_angles);
  return lengths.IsEmpty() ? std::string() : std::string(lengths.First().ToCString());
}

std::string iges_length_unit(IGESCAFControl_Reader& reader) {
  const Handle(IGESData_IGESModel) model = reader.IGESModel();
  if (model.IsNull()) return {};
  const Handle(TCollection_HAsciiString) unit = model->GlobalSection().UnitName();
  return unit.IsNull() ? std::string() : std::string(unit->ToCString());
}

}  // namespace

std::expected<CadDocument, Error> read_cad_document(const std::filesystem::path& path, const std::string& name,
                                                    const CadReadOptions& options, Deadline& deadline) {
  const std::string ext = lower_extension(path);
  const std::string format = ext == ".iges" || ext == ".igs" ? "iges" : "step";
  if (auto bad = check_edges(path, name, format, options)) return std::unexpected(*bad);
  try {
    if (format == "step") {
      STEPCAFControl_Reader reader;
      if (reader.ReadFile(path.c_str()) != IFSelect_RetDone)
        return std::unexpected(error(ErrorCode::parse_error, fmt::format("{}: the STEP reader rejected the file "
                                                                         "(malformed entities; see the notes)", name)));
      auto doc = transfer(reader, name, format, deadline);
      if (doc) doc->length_unit = step_length_unit(reader);
      return doc;
    }
    IGESCAFControl_Reader reader;
    if (reader.ReadFile(path.c_str()) != IFSelect_RetDone)
      return std::unexpected(error(ErrorCode::parse_error, fmt::format("{}: the IGES reader rejected the file", name)));
    auto doc = transfer(reader, name, format, deadline);
    if (doc) doc->length_unit = iges_length_unit(reader);
    return doc;
  } catch (const Standard_Failure& failure) {
    return std::unexpected(error(ErrorCode::parse_error, fmt::format("{}: OpenCASCADE failed reading it: {}", name,
                                                                     failure.GetMessageString())));
  }
}

}  // namespace lamina::step_detail
