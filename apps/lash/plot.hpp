#pragma once
// Plots through gnuplot (Debian gnuplot-nox, pngcairo terminal). The PNG is
// rendered to a temporary file and renamed, so a failed plot leaves nothing.
#include <filesystem>
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

/// A fresh private directory next to `target` (`<target>.tmp.XXXXXX`, mkdtemp: created
/// exclusively, mode 0700), so nothing planted at a predictable name is followed; removed with
/// its contents on destruction. The directory of `target` must exist and be writable: InputError
/// naming `target` and `option` otherwise.
class PrivateTempDir {
 public:
  PrivateTempDir(const std::string& target, const std::string& option);
  ~PrivateTempDir();
  PrivateTempDir(const PrivateTempDir&) = delete;
  PrivateTempDir& operator=(const PrivateTempDir&) = delete;
  const std::filesystem::path& path() const noexcept { return dir_; }

 private:
  std::filesystem::path dir_;
};

/// Runs an arbitrary gnuplot script whose output goes to `png_path` (the script must
/// `set output '<OUTPUT>'`; the placeholder is replaced by a temporary path).
void run_gnuplot(const std::string& script, const std::string& png_path);

}  // namespace lash::cli
