#pragma once
// The tables of `lamina plan` a person reads, printed from the typed report (report.json's
// struct, lamina/core/plan_report.hpp), so the tables and the file always agree.
#include "lamina/core/plan_report.hpp"

#include <cstdio>

namespace lamina::cli {

// The layer table, the deviation table, the stack line, shortfalls and timings.
void print_plan_tables(std::FILE* out, const PlanReport& report, bool all_rows);

// The part as cut beside the plan (--as-cut): per layer and in total.
void print_as_cut_table(std::FILE* out, const ReportAsCut& a, bool all_rows);

}  // namespace lamina::cli
