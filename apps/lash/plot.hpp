#pragma once
// Plots through gnuplot (Debian gnuplot-nox, pngcairo terminal). The PNG is
// rendered to a temporary file and renamed, so a failed plot leaves nothing.
#include <string>
#include <vector>

namespace lash::cli {

struct PlotSeries {
  std::string x_column;  ///< column name in the CSV
  std::string y_column;
  std::string title;
  int panel = 0;         ///< panels are stacked top to bottom
};

struct PlotPanel {
  std::string ylabel;
  std::string xlabel;
};

/// Renders `series` from `csv_path` into `png_path`. Throws InputError if gnuplot fails.
void plot_csv(const std::string& csv_path, const std::string& png_path, const std::string& title,
              const std::vector<PlotPanel>& panels, const std::vector<PlotSeries>& series);

/// Runs an arbitrary gnuplot script whose output goes to `png_path` (the script must
/// `set output '<OUTPUT>'`; the placeholder is replaced by a temporary path).
void run_gnuplot(const std::string& script, const std::string& png_path);

}  // namespace lash::cli
