#pragma once
// The sections of cut sheets (lamina-sim --as-cut, docs/jet.md), read at the CLI's edge for
// `lamina plan --as-cut DIR`: DIR/sheet-<n>.ascut.json for every sheet of the plan, each checked
// to have been cut from this plan's own program (its FNV-1a fingerprint), so a record of another
// plan's program is never measured against this one.
#include "lamina/core/as_cut.hpp"
#include "lamina/core/error.hpp"
#include "lamina/core/plan_job.hpp"
#include "lamina/core/plan_report.hpp"

#include <expected>
#include <string>
#include <string_view>
#include <vector>

namespace lamina::cli {

// FNV-1a, 64 bits, 16 hex digits, as lamina-sim writes it. Written again there on purpose: the
// simulator links nothing of Lamina's (it is the machine, an independent peer), and both sides
// are tested against FNV-1a's published values, so the two cannot drift apart unseen.
std::string program_fingerprint(std::string_view program);

// parse_error naming the file and the key: "sheet-2.ascut.json: sections[3].pieces[0]: …".
std::expected<CutSheet, Error> parse_cut_sheet(std::string_view text, const std::string& source, int sheet,
                                               std::string_view program);

// Every sheet's record from DIR; io_error naming a missing one.
std::expected<std::vector<CutSheet>, Error> read_cut_sheets(const std::string& dir, const CamResult& cam);

ReportAsCut report_as_cut(const AsCutDeviation& d, const std::string& dir);

}  // namespace lamina::cli
