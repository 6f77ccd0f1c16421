#include "plot.hpp"

#include <unistd.h>

#include <sys/wait.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>

#include <fmt/core.h>

#include "lash/io/atomic_file.hpp"
#include "lash/io/error.hpp"

namespace lash::cli {

PrivateTempDir::PrivateTempDir(const std::string& target, const std::string& option) {
  const std::filesystem::path dir =
      std::filesystem::path(target).has_parent_path() ? std::filesystem::path(target).parent_path() : ".";
  std::error_code dec;
  if (!std::filesystem::is_directory(dir, dec))
    throw InputError(target, 0, option, "cannot write: directory " + dir.string() + " does not exist");
  if (::access(dir.c_str(), W_OK) != 0)
    throw InputError(target, 0, option, "cannot write in directory " + dir.string() + ": " + std::strerror(errno));
  std::string dir_template = target + ".tmp.XXXXXX";
  if (!::mkdtemp(dir_template.data()))
    throw InputError(target, 0, option,
                     "cannot create a temporary directory next to it: " + std::string(std::strerror(errno)));
  dir_ = dir_template;
}

PrivateTempDir::~PrivateTempDir() {
  std::error_code e;
  std::filesystem::remove_all(dir_, e);
}

void run_gnuplot(const std::string& script_in, const std::string& png_path) {
  // gnuplot's script and picture go to a fresh private directory next to the target
  const PrivateTempDir tmp(png_path, "--plot");
  const std::filesystem::path& work = tmp.path();
  const std::string tmp_png = (work / "plot.png").string();
  std::string script = script_in;
  for (auto pos = script.find("<OUTPUT>"); pos != std::string::npos; pos = script.find("<OUTPUT>"))
    script.replace(pos, 8, tmp_png);
  const std::string gp = (work / "plot.gp").string();
  {
    std::ofstream f(gp);
    f << script;
    f.flush();
    if (!f) throw InputError(png_path, 0, "--plot", "cannot write the gnuplot script " + gp + ": " + std::strerror(errno));
  }
  const std::string cmd = "gnuplot '" + gp + "' 2>&1";
  FILE* p = ::popen(cmd.c_str(), "r");
  std::string out;
  int status = -1;
  if (p) {
    char buf[512];
    while (std::fgets(buf, sizeof buf, p)) out += buf;
    status = ::pclose(p);
  }
  std::error_code ec;
  if (status != 0 || !std::filesystem::exists(tmp_png)) {
    if (status != -1 && WIFEXITED(status) && WEXITSTATUS(status) == 127)
      throw InputError(png_path, 0, "--plot", "gnuplot not found on PATH (install gnuplot-nox): " + out);
    throw InputError(png_path, 0, "--plot", "gnuplot failed: " + out);
  }
  std::filesystem::rename(tmp_png, png_path, ec);
  if (ec) throw InputError(png_path, 0, "--plot", "cannot write: " + ec.message());
}

void plot_csv(const std::string& csv_path, const std::string& png_path, const std::string& title,
              const std::vector<PlotPanel>& panels, const std::vector<PlotSeries>& series) {
  if (is_stream_output(csv_path))
    throw InputError(png_path, 0, "--plot", "needs -o to name a regular file (the plot reads it back), not " + csv_path);
  const int n = static_cast<int>(panels.size());
  std::string s;
  s += fmt::format("set terminal pngcairo noenhanced size 1200,{} font 'sans,10'\n", 300 * n + 60);
  s += "set output '<OUTPUT>'\nset datafile separator ','\nset key autotitle columnhead\nset grid\n";
  s += fmt::format("set multiplot layout {},1 title '{}'\n", n, title);
  for (int p = 0; p < n; ++p) {
    s += fmt::format("set xlabel '{}'\nset ylabel '{}'\n", panels[p].xlabel, panels[p].ylabel);
    std::string plot;
    for (const auto& se : series) {
      if (se.panel != p) continue;
      plot += plot.empty() ? "plot " : ", ";
      plot += fmt::format("'{}' using (column('{}')):(column('{}')) with lines title '{}'", csv_path, se.x_column,
                          se.y_column, se.title);
    }
    s += plot + "\n";
  }
  s += "unset multiplot\n";
  run_gnuplot(s, png_path);
}

}  // namespace lash::cli
