// read_cad_file: OCCT's messages caught, the document read and tessellated within the deadline,
// and what OCCT said kept as the soup's notes.
#include "lamina/step/cad_reader.hpp"

#include "cad_document.hpp"
#include "cad_tessellate.hpp"
#include "occt_session.hpp"

#include <Standard_Failure.hxx>

#include <fmt/format.h>

#include <algorithm>
#include <cctype>

namespace lamina {

namespace {

// At most this many of OCCT's distinct messages become notes (a broken file can say thousands).
constexpr std::size_t kMaxReaderNotes = 20;

void keep_messages(const step_detail::CaughtMessages& caught, TriangleSoup& soup, bool quote) {
  const auto messages = caught.messages();
  std::size_t shown = 0;
  for (const auto& m : messages) {
    if (shown++ == kMaxReaderNotes) {
      soup.notes.push_back({"reader_messages", fmt::format("… and {} more distinct reader messages", messages.size() - kMaxReaderNotes)});
      break;
    }
    // OCCT's messages quote entity text from the file; a file someone else named keeps its bytes.
    soup.notes.push_back({"reader_message", quote ? fmt::format("{} (×{})", m.text, m.count)
                                                  : fmt::format("a reader message of {} bytes (×{})", m.text.size(), m.count)});
  }
}

}  // namespace

std::expected<TriangleSoup, Error> read_cad_file(const std::filesystem::path& path, const CadReadOptions& options) {
  const std::string name = path.string();
  if (!(options.chord_tolerance_mm > 0) || !(options.angle_tolerance_rad > 0))
    return std::unexpected(Error{ErrorCode::invalid_argument,
                                 fmt::format("{}: the chord tolerance ({} mm) and the angle tolerance ({} rad) must be > 0",
                                             name, options.chord_tolerance_mm, options.angle_tolerance_rad)});
  step_detail::CaughtMessages caught;
  step_detail::Deadline deadline(options.max_seconds);
  try {
    auto doc = step_detail::read_cad_document(path, name, options, deadline);
    if (!doc) return std::unexpected(doc.error());
    if (doc->solids.empty()) {
      const std::string what = doc->faces_outside_solids > 0
                                   ? fmt::format("{} faces but no solid (a surface model): export the part as a solid", doc->faces_outside_solids)
                                   : std::string("no shape at all");
      return std::unexpected(Error{ErrorCode::empty_mesh, fmt::format("{}: the {} file holds {}", name,
                                                                       doc->format == "step" ? "STEP" : "IGES", what)});
    }
    auto soup = step_detail::tessellate(*doc, name, options, deadline);
    if (!soup) return soup;
    if (doc->faces_outside_solids > 0)
      soup->notes.push_back({"faces_outside_solids", fmt::format("{} faces belong to no solid and were left out",
                                                                 doc->faces_outside_solids)});
    if (!doc->length_unit.empty())
      soup->notes.push_back({"length_unit", fmt::format("the file's length unit is {}; read in mm", doc->length_unit)});
    keep_messages(caught, *soup, options.quote_file_text);
    return soup;
  } catch (const Standard_Failure& failure) {
    return std::unexpected(Error{ErrorCode::parse_error,
                                 fmt::format("{}: OpenCASCADE failed: {}", name, failure.GetMessageString())});
  }
}

}  // namespace lamina
