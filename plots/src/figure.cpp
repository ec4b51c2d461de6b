#include "geomint/plots/figure.hpp"

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include <gnuplot-iostream.h>

#include "geomint/error.hpp"
#include "geomint/io.hpp"

namespace geomint::plots {

std::size_t TsvTable::column(const std::string& name) const {
  for (std::size_t i = 0; i < columns.size(); ++i)
    if (columns[i] == name) return i;
  throw InputError("TSV has no column '" + name + "'");
}

double TsvTable::number(std::size_t row, const std::string& name) const {
  return std::strtod(rows.at(row).at(column(name)).c_str(), nullptr);
}

const std::string& TsvTable::text(std::size_t row, const std::string& name) const {
  return rows.at(row).at(column(name));
}

std::vector<double> TsvTable::numbers(const std::string& name, const std::function<bool(std::size_t)>& keep) const {
  const std::size_t c = column(name);
  std::vector<double> out;
  for (std::size_t r = 0; r < rows.size(); ++r)
    if (keep(r)) out.push_back(std::strtod(rows[r][c].c_str(), nullptr));
  return out;
}

TsvTable read_tsv(const std::filesystem::path& path) {
  std::ifstream in(path);
  require(static_cast<bool>(in), "cannot read '" + path.string() + "'");
  TsvTable t;
  std::string line;
  auto split = [](const std::string& s) {
    std::vector<std::string> cells;
    std::stringstream ss(s);
    std::string cell;
    while (std::getline(ss, cell, '\t')) cells.push_back(cell);
    return cells;
  };
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    if (t.columns.empty())
      t.columns = split(line);
    else
      t.rows.push_back(split(line));
  }
  return t;
}

std::string slope_label(const std::string& name, double slope) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2f", slope);
  return name + " (slope " + (std::isfinite(slope) ? std::string(buf) : std::string("n/a")) + ")";
}

std::string style_for(const std::string& scheme, const std::string& with) {
  static const std::vector<std::pair<std::string, std::string>> colors = {
      {"la", "#d95f02"},          {"la-printed", "#7570b3"},  {"contact", "#1b9e77"},
      {"leapfrog", "#666666"},    {"leapfrog-ref", "#222222"}, {"contact-sym", "#66a61e"},
      {"la-nh", "#d95f02"},       {"contact-nh", "#1b9e77"},   {"reference", "#222222"},
      {"la-midpoint", "#e7298a"}, {"la-trapezoid", "#666666"}, {"contact-trapezoid", "#66a61e"}};
  for (const auto& [n, c] : colors)
    if (n == scheme) return with + " lw 1.5 lc rgb '" + c + "'";
  return with + " lw 1.5";
}

namespace {

std::string quote(const std::string& s) {
  std::string q = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') q += '\\';
    q += c;
  }
  return q + "\"";
}

// Points per row of a heat map (x varies fastest, rows of constant y, every row as long).
std::size_t grid_nx(const Series& s) {
  std::size_t nx = 1;
  while (nx < s.y.size() && s.y[nx] == s.y[0]) ++nx;
  if (s.z.size() % nx != 0 || s.x.size() != s.z.size() || s.y.size() != s.z.size())
    throw std::runtime_error("heat map '" + s.title + "' is not a regular grid");
  return nx;
}

void render(const Figure& fig, const std::string& terminal, const std::filesystem::path& tmp) {
  // Drop non-finite points: a failed run is a missing point, never a NaN in a figure.
  std::vector<Panel> panels = fig.panels;
  for (auto& p : panels)
    for (auto& s : p.series) {
      if (!s.z.empty()) continue;  // heat maps keep their grid; NaN cells are drawn as background
      const bool bars = !s.ylow.empty();
      Series clean{{}, {}, s.title, s.style, {}};
      for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i)
        if (std::isfinite(s.x[i]) && std::isfinite(s.y[i]) &&
            (!bars || (std::isfinite(s.ylow.at(i)) && std::isfinite(s.yhigh.at(i))))) {
          clean.x.push_back(s.x[i]);
          clean.y.push_back(s.y[i]);
          if (bars) {
            clean.ylow.push_back(s.ylow[i]);
            clean.yhigh.push_back(s.yhigh[i]);
          }
        }
      s = std::move(clean);
    }
  {
    Gnuplot gp("gnuplot");
    gp << "set terminal " << terminal << "\n";
    gp << "set output " << quote(tmp.string()) << "\n";
    gp << "set encoding utf8\nset grid lc rgb '#dddddd'\nset key box opaque samplen 2 font ',9'\n";
    const bool multi = fig.rows * fig.cols > 1;
    if (multi)
      gp << "set multiplot layout " << fig.rows << "," << fig.cols << " title " << quote(fig.title) << "\n";
    else
      gp << "set title " << quote(fig.title) << "\n";
    for (const auto& p : panels) {
      gp << "reset session\nset grid lc rgb '#dddddd'\nset key box opaque samplen 2 font ',9'\n" << p.setup << "\n";
      std::string cmd = "plot ";
      bool first = true;
      for (const auto& s : p.series) {
        if (s.x.empty()) continue;  // every point of this series failed
        // Points go as binary records: gnuplot reads inline text a few bytes per system call, which made
        // figures of tens of thousands of points take seconds.
        // Heat maps go as a binary grid of (x, y, z) records, x varying fastest, nx per row.
        // Error bars: (x, y, ylow, yhigh) records.
        cmd += (first ? "" : ", ") +
               (!s.z.empty() ? "'-' binary record=(" + std::to_string(grid_nx(s)) + "," +
                                   std::to_string(s.z.size() / grid_nx(s)) +
                                   ") format='%float64%float64%float64' using 1:2:3 with "
                : !s.ylow.empty() ? "'-' binary record=" + std::to_string(s.x.size()) +
                                        " format='%float64%float64%float64%float64' using 1:2:3:4 with "
                                  : "'-' binary" + gp.binFmt1d(std::make_pair(s.x, s.y), "record") + " using 1:2 with ") +
               s.style + (s.title.empty() ? std::string(" notitle") : " title " + quote(s.title));
        first = false;
      }
      if (!p.extra_plots.empty()) {
        cmd += (first ? "" : ", ") + p.extra_plots;
        first = false;
      }
      if (first)  // every point failed: say so in an empty panel (gnuplot refuses to plot nothing)
        cmd = "unset logscale\nset xrange [0:1]\nset yrange [0:1]\nunset xtics\nunset ytics\n"
              "set label 'no data: every run in this panel failed' at graph 0.5, 0.5 center\nplot -1 notitle";
      gp << cmd << "\n";
      for (const auto& s : p.series) {
        if (s.x.empty()) continue;
        if (!s.ylow.empty()) {
          std::vector<double> rec;
          rec.reserve(4 * s.x.size());
          for (std::size_t i = 0; i < s.x.size(); ++i) rec.insert(rec.end(), {s.x[i], s.y[i], s.ylow[i], s.yhigh[i]});
          gp.write(reinterpret_cast<const char*>(rec.data()), static_cast<std::streamsize>(rec.size() * sizeof(double)));
        } else if (s.z.empty()) {
          gp.sendBinary1d(std::make_pair(s.x, s.y));
        } else {
          std::vector<double> xyz;
          xyz.reserve(3 * s.z.size());
          for (std::size_t i = 0; i < s.z.size(); ++i) xyz.insert(xyz.end(), {s.x[i], s.y[i], s.z[i]});
          gp.write(reinterpret_cast<const char*>(xyz.data()), static_cast<std::streamsize>(xyz.size() * sizeof(double)));
        }
      }
    }
    if (multi) gp << "unset multiplot\n";
    gp << "set output\n";
  }  // gnuplot exits and the file is complete when gp is destroyed
}

}  // namespace

void Figure::draw(const std::filesystem::path& stem) const {
  namespace fs = std::filesystem;
  const std::string size_px = std::to_string(static_cast<int>(width_in * 140)) + "," +
                              std::to_string(static_cast<int>(height_in * 140));
  const std::string size_in = std::to_string(width_in) + "in," + std::to_string(height_in) + "in";
  const struct {
    const char* ext;
    std::string terminal;
  } outs[] = {{".png", "pngcairo enhanced size " + size_px + " font 'Sans,10'"},
              {".pdf", "pdfcairo enhanced size " + size_in + " font 'Sans,8'"}};
  for (const auto& o : outs) {
    fs::path final_path = stem;
    final_path += o.ext;
    fs::path tmp = final_path;
    tmp += ".tmp";
    render(*this, o.terminal, tmp);
    std::error_code ec;
    if (!fs::exists(tmp) || fs::file_size(tmp) == 0) {
      fs::remove(tmp, ec);
      throw std::runtime_error("gnuplot did not write " + final_path.string());
    }
    fs::rename(tmp, final_path, ec);
    if (ec) throw std::runtime_error("cannot rename " + tmp.string() + ": " + ec.message());
  }
}

}  // namespace geomint::plots
