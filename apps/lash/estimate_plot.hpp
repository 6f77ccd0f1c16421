#pragma once
// `lash estimate --plot`: one panel per parameter (both sides, own axis and unit), then the
// measured against the free-run simulated output; legends outside the data.
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace lash::cli {

/// `csv` holds t, y, y_sim and the parameter columns `param_names` ("a1_r", "c_l", "d", …).
/// The output panel shows the last 20 s (or all of a shorter record) so single periods stay visible.
void plot_estimate(const std::string& csv, const std::string& png, const std::string& title,
                   const std::vector<std::string>& param_names, double t_end_s,
                   const std::map<std::string, std::pair<double, double>>& ci95 = {},
                   const std::set<std::string>& empty_columns = {});
/// ci95: shaded as a band over the whole time axis, the final estimate's 95 % interval per column.
/// empty_columns: columns without a finite value (a side never identified); a panel whose columns
/// are all empty is drawn with fixed axes and the note "not identified" instead of failing.

}  // namespace lash::cli
