#pragma once
// Figures in the house style, drawn with gnuplot from data read back from a saved TSV (so a figure always shows
// what the file holds). Each figure is written as PNG and PDF. gnuplot is started without a shell, in a folder of
// ours (the run's staging folder, see OutputRun in geomint/io.hpp), and sees only names we chose: the output path
// never reaches it; titles go as single-quoted strings (no backquote or macro substitution). Its exit status and
// error output are checked, and a file it could not finish (full disk) is an error: the previous figure stays.
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace geomint::plots {

// A tidy TSV read back: '#' lines skipped, first other line is the column names.
struct TsvTable {
  std::vector<std::string> columns;
  std::vector<std::vector<std::string>> rows;
  std::size_t column(const std::string& name) const;  // throws if absent
  double number(std::size_t row, const std::string& name) const;
  const std::string& text(std::size_t row, const std::string& name) const;
  // Values of column `name` over the rows accepted by `keep` (in file order).
  std::vector<double> numbers(const std::string& name, const std::function<bool(std::size_t)>& keep) const;
};
TsvTable read_tsv(const std::filesystem::path& path);

struct Series {
  Series() = default;
  Series(std::vector<double> x_, std::vector<double> y_, std::string title_, std::string style_ = "lines",
         std::vector<double> z_ = {})
      : x(std::move(x_)), y(std::move(y_)), title(std::move(title_)), style(std::move(style_)), z(std::move(z_)) {}
  std::vector<double> x, y;
  std::string title;
  std::string style = "lines";  // gnuplot "with" clause
  std::vector<double> z;        // non-empty: a heat map, x/y on a regular grid (row-major), style "image"
  std::vector<double> ylow, yhigh;  // non-empty: error bars (style "yerrorbars" or "points" with "errorbars")
};

struct Panel {
  std::string setup;  // gnuplot commands: labels, log scales, ranges, key
  std::vector<Series> series;
  std::string extra_plots;  // extra plot items (e.g. reference slope functions), appended after series
};

struct Figure {
  std::string title;
  int rows = 1, cols = 1;
  std::vector<Panel> panels;
  double width_in = 7, height_in = 4.5;
  // Writes stem.png and stem.pdf. Throws (with gnuplot's message) when gnuplot fails or cannot finish a file.
  // A panel with no point it can show (all non-finite, or none positive on a log axis) says so in a label.
  void draw(const std::filesystem::path& stem) const;
};

// A fixed colour per scheme name, so a scheme looks the same in every figure.
std::string style_for(const std::string& scheme, const std::string& with = "lines");

// Log-log helper: one panel of err vs h series with fitted slopes in the titles and reference slopes.
std::string slope_label(const std::string& name, double slope);

}  // namespace geomint::plots
