#include "estimate_plot.hpp"

#include <algorithm>

#include <fmt/core.h>

#include "plot.hpp"

namespace lash::cli {
namespace {
struct Panel {
  std::string base;                 // a1, b1, c, d
  std::vector<std::string> columns;  // a1_r, a1_l
};
std::string unit_of(const std::string& base) {
  if (base == "a1") return "a1 [-]";
  if (base == "b1") return "b1 [y unit / v unit]";
  if (base == "c") return "deadzone edge c [v unit]";
  if (base == "d") return "deadband half-width d [y unit]";
  return base;
}
std::string side_title(const std::string& col) {
  if (col.size() > 2 && col.compare(col.size() - 2, 2, "_r") == 0) return col.substr(0, col.size() - 2) + " right";
  if (col.size() > 2 && col.compare(col.size() - 2, 2, "_l") == 0) return col.substr(0, col.size() - 2) + " left";
  return col;
}
}  // namespace

void plot_estimate(const std::string& csv, const std::string& png, const std::string& title,
                   const std::vector<std::string>& param_names, double t_end_s,
                   const std::map<std::string, std::pair<double, double>>& ci95,
                   const std::set<std::string>& empty_columns) {
  std::vector<Panel> panels;
  for (const auto& n : param_names) {
    const std::string base = n.substr(0, n.find('_'));
    auto it = panels.begin();
    while (it != panels.end() && it->base != base) ++it;
    if (it == panels.end()) panels.push_back({base, {n}});
    else it->columns.push_back(n);
  }
  const int rows = static_cast<int>(panels.size()) + 1;
  std::string s;
  s += fmt::format("set terminal pngcairo noenhanced size 1200,{} font 'sans,10'\n", 230 * rows + 80);
  s += "set output '<OUTPUT>'\nset datafile separator ','\nset grid\n";
  s += "set key outside right top vertical Left reverse width 2\nset lmargin 12\nset rmargin 28\n";
  s += fmt::format("set multiplot layout {},1 title '{}'\n", rows, title);
  const char* colors[] = {"#1f77b4", "#d62728"};
  for (const auto& p : panels) {
    s += fmt::format("set xlabel 't [s]'\nset ylabel '{}'\n", unit_of(p.base));
    std::string plot;
    int obj = 0;
    for (std::size_t i = 0; i < p.columns.size(); ++i) {
      const auto band = ci95.find(p.columns[i]);
      if (band == ci95.end() || !(band->second.first <= band->second.second)) continue;
      s += fmt::format(
          "set object {} rectangle from graph 0, first {:.17g} to graph 1, first {:.17g} fc rgb '{}' "
          "fs transparent solid 0.18 noborder behind\n",
          ++obj, band->second.first, band->second.second, colors[i % 2]);
      plot += plot.empty() ? "plot " : ", ";
      plot += fmt::format("NaN with boxes fs transparent solid 0.18 noborder lc rgb '{}' title '{} 95 % CI'",
                          colors[i % 2], side_title(p.columns[i]));
    }
    for (std::size_t i = 0; i < p.columns.size(); ++i) {
      plot += plot.empty() ? "plot " : ", ";
      plot += fmt::format("'{}' using (column('t')):(column('{}')) with lines lw 1.5 lc rgb '{}' title '{}'", csv,
                          p.columns[i], colors[i % 2], side_title(p.columns[i]));
    }
    // gnuplot cannot autoscale a panel with no defined point: fixed axes and a note instead
    const bool none = std::all_of(p.columns.begin(), p.columns.end(),
                                  [&](const std::string& c) { return empty_columns.count(c) > 0; });
    if (none)
      s += fmt::format("set xrange [0:{:.17g}]\nset yrange [-1:1]\nset label 1 'not identified: no estimate of {}' "
                       "at graph 0.5, graph 0.5 center\n",
                       t_end_s > 0 ? t_end_s : 1.0, p.base);
    s += plot + "\n";
    if (none) s += "unset label 1\nset autoscale x\nset autoscale y\n";
    for (int k = 1; k <= obj; ++k) s += fmt::format("unset object {}\n", k);
  }
  s += fmt::format("set xlabel 't [s] (last {:g} s)'\nset ylabel 'output y [y unit]'\nset xrange [{}:{}]\n",
                   t_end_s > 20.0 ? 20.0 : t_end_s, t_end_s > 20.0 ? t_end_s - 20.0 : 0.0, t_end_s);
  s += fmt::format(
      "plot '{0}' using (column('t')):(column('y')) with lines lc rgb '#999999' title 'y measured', "
      "'{0}' using (column('t')):(column('y_sim')) with lines lw 1.2 lc rgb '#d62728' title 'y free run'\n",
      csv);
  s += "unset multiplot\n";
  run_gnuplot(s, png);
}

}  // namespace lash::cli
