// lash.sweep: a campaign run on the library's thread pool; rows as in the results CSV.
#include <optional>

#include "convert.hpp"
#include "lash/experiments/campaign.hpp"
#include "lash/experiments/sweep.hpp"

namespace lash::py {

void bind_sweep(pyb::module_& m) {
  m.def(
      "_sweep_csv",
      [](const std::string& path, unsigned jobs) {
        const sweep::Campaign c = sweep::load_campaign(path);
        std::optional<std::vector<sweep::RunResult>> results;
        {
          pyb::gil_scoped_release nogil;
          results.emplace(sweep::run_campaign(c, jobs));
        }
        return sweep::results_csv_text(c, *results);
      },
      pyb::arg("campaign_path"), pyb::arg("jobs") = 0u, "The results CSV text of `lash sweep` (use lash.sweep).");
}

}  // namespace lash::py
