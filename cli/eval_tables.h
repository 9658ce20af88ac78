#pragma once
// The result tables of `focal eval`'s analytic suite (eval_tables.cpp): every metric as CSV and
// the relative H error per case and method as Markdown, with focal default's wins.

#include <string>
#include <vector>

#include "eval_cases.h"
#include "eval_estimators.h"
#include "focal/evaluation/evaluation.h"

namespace focal::cli::eval {

/// One row of the tables: a case, a method and its errors there.
struct Row {
  Case c;
  std::string method;
  Evaluation e;
};

/// x with 4 significant digits, "nan" for NaN: the tables' number format.
std::string number(double x);

/// The suite's every metric, one row per case and method, as CSV at `path`.
void write_csv_table(const std::string& path, const std::vector<Row>& rows);

/// Markdown: one row per case, the relative RMS error of H per method, the best in bold.
std::string markdown_table(const std::vector<Row>& rows, const std::vector<Estimator>& ms,
                           const EvalFlags& f);

}  // namespace focal::cli::eval
