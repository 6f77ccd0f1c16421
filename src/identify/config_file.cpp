#include "lash/identify/config_file.hpp"

#include <sstream>
#include <string_view>

#include "lash/identify/config_fields.hpp"

namespace lash {

void read_estimator_config(TomlTable& t, EstimatorConfig& c, EstimationJob* job) {
  // the model first: it decides nothing here (a file may hold keys of other models, e.g. a
  // campaign's [estimator] shared by rigs), but its error comes before the others
  for (std::string_view table : {"", "rls", "noise"}) {
    std::optional<TomlTable> sub;
    if (!table.empty()) {
      sub = t.table_opt(table);
      if (!sub) continue;
    }
    TomlTable& tt = sub ? *sub : t;
    for (const ConfigField& f : estimator_fields())
      if (table == f.table) read_field(tt, f, c);
    if (sub) sub->finish();
  }
  if (job) {
    if (auto cols = t.strings_opt("columns")) {
      if (cols->size() != 3) t.fail("columns", "expected three names [t, v, y]");
      job->columns = *cols;
    }
    if (auto w = t.numbers_opt("nrmse_window")) {
      if (w->size() != 2 || !((*w)[0] < (*w)[1])) t.fail("nrmse_window", "expected [t0, t1] with t0 < t1 [s]");
      job->nrmse_t0_s = (*w)[0];
      job->nrmse_t1_s = (*w)[1];
    }
  }
  t.finish();
}

std::string config_to_toml(const EstimatorConfig& c, const EstimationJob* job) {
  std::ostringstream o;
  o << "# lash estimate settings (docs/identification.md); lash estimate --config FILE reads them back\n";
  o << "# (the settings model " << to_string(c.model) << " reads; a commented line is a non-finite value: the default)\n";
  for (std::string_view table : {"", "rls", "noise"}) {
    if (!table.empty()) o << "\n[" << table << "]\n";
    for (const ConfigField& f : estimator_fields()) {
      if (table != f.table || !contains(f.models, c.model)) continue;
      if (!field_finite(f, c)) o << "# ";
      o << f.key << " = " << field_toml_value(f, c) << "\n";
      if (job && table.empty() && std::string_view(f.key) == "fit_start") {  // the job's keys beside it
        o << "columns = [" << toml_string(job->columns[0]) << ", " << toml_string(job->columns[1]) << ", "
          << toml_string(job->columns[2]) << "]\n";
        if (job->nrmse_t1_s >= 0)  // an open end is the default
          o << "nrmse_window = [" << toml_number(job->nrmse_t0_s) << ", " << toml_number(job->nrmse_t1_s) << "]\n";
      }
    }
  }
  return o.str();
}

}  // namespace lash
