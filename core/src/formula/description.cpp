#include "geomint/formula/description.hpp"

#include <cctype>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>
#include <system_error>

#include "geomint/error.hpp"
#include "geomint/formula/option_names.hpp"
#include "geomint/text.hpp"

namespace geomint::formula {

std::string Where::at(int column_in_formula) const {
  if (line > 0) return source + ":" + std::to_string(line) + ":" + std::to_string(column + column_in_formula - 1);
  return source + ", column " + std::to_string(column_in_formula);
}

std::string Where::place() const { return line > 0 ? source + ":" + std::to_string(line) : source; }

FormulaText formula_text(std::string text, std::string field) {
  FormulaText f;
  f.text = std::move(text);
  f.where.source = std::move(field);
  return f;
}

namespace {

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t");
  if (b == std::string::npos) return "";
  const auto e = s.find_last_not_of(" \t");
  return s.substr(b, e - b + 1);
}

bool identifier(const std::string& s) {
  if (s.empty() || !(std::isalpha(static_cast<unsigned char>(s[0])) || s[0] == '_')) return false;
  for (char c : s)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_')) return false;
  return true;
}

// "F12" -> ("F", 12); false unless the key is a prefix followed by a positive integer without leading zeros.
bool indexed(const std::string& key, const std::string& prefix, int& index) {
  if (key.size() <= prefix.size() || key.compare(0, prefix.size(), prefix) != 0) return false;
  const std::string digits = key.substr(prefix.size());
  if (digits[0] == '0' || digits.size() > 3) return false;
  for (char c : digits)
    if (!std::isdigit(static_cast<unsigned char>(c))) return false;
  index = std::stoi(digits);
  return true;
}

const char* const sections[] = {"system", "parameters", "definitions", "dynamics", "constraints", "initial", "exact"};

class Reader {
 public:
  Reader(const std::string& source) { d_.origin.source = source; }

  SystemDescription run(const std::string& text) {
    std::istringstream in(text);
    std::string raw;
    while (std::getline(in, raw)) {
      ++line_;
      if (!raw.empty() && raw.back() == '\r') raw.pop_back();
      // A byte order mark is how some editors begin UTF-8 text: not part of the first line.
      if (line_ == 1 && raw.compare(0, 3, "\xef\xbb\xbf") == 0) raw.erase(0, 3);
      printable(raw);
      line(raw);
    }
    finish();
    return std::move(d_);
  }

 private:
  [[noreturn]] void fail(const std::string& what, int column = 0) const {
    throw InputError(d_.origin.source + ":" + std::to_string(line_) + (column > 0 ? ":" + std::to_string(column) : "") +
                     ": " + what);
  }

  // Text only: a control byte would reach the terminal in a message (an ESC sequence acts on it, a NUL cuts the
  // message), and a byte that is not UTF-8 (a Latin-1 degree sign in a comment) could not be shown or handed to
  // Python as text.
  void printable(const std::string& raw) const {
    const std::size_t at = first_unprintable(raw, "\t");
    if (at == std::string::npos) return;
    const auto c = static_cast<unsigned char>(raw[at]);
    char byte[8];
    std::snprintf(byte, sizeof byte, "0x%02x", c);
    if (c < 0x20 || c == 0x7f || (c == 0xc2 && at + 1 < raw.size() && static_cast<unsigned char>(raw[at + 1]) < 0xa0))
      fail(std::string("control character (byte ") + byte + (c == '\r' ? ", a carriage return inside the line" : "") +
               "): a system file is plain text",
           static_cast<int>(at) + 1);
    fail(std::string("byte ") + byte + " is not UTF-8 text: save the file as UTF-8", static_cast<int>(at) + 1);
  }

  void line(const std::string& raw) {
    const auto hash = raw.find('#');
    const std::string body = raw.substr(0, hash);
    const std::string comment = hash == std::string::npos ? "" : trim(raw.substr(hash + 1));
    const std::string content = trim(body);
    if (content.empty()) return;
    if (content.front() == '[') {
      if (content.back() != ']') fail("a section header is written [name]");
      const std::string name = trim(content.substr(1, content.size() - 2));
      bool known = false;
      for (const char* s : sections) known = known || name == s;
      if (!known)
        fail("unknown section [" + name + "] (sections: [system] [parameters] [definitions] [dynamics] [constraints] [initial] [exact])");
      if (seen_sections_.count(name)) fail("section [" + name + "] appears twice (first at line " + std::to_string(seen_sections_[name]) + ")");
      seen_sections_[name] = line_;
      section_ = name;
      return;
    }
    const auto eq = body.find('=');
    if (eq == std::string::npos) fail("expected 'key = value' (or a [section])");
    const std::string key = trim(body.substr(0, eq));
    const auto vstart = body.find_first_not_of(" \t", eq + 1);
    if (key.empty()) fail("a line starts with '=': the key is missing");
    if (!identifier(key)) fail("'" + key + "' is not a name (letters, digits and '_', not starting with a digit)");
    if (vstart == std::string::npos) fail("'" + key + " =' has no value", static_cast<int>(eq) + 2);
    if (section_.empty()) fail("'" + key + "' comes before any section (start with [system])");
    const std::string value = trim(body.substr(vstart));
    const std::string full = section_ + "." + key;
    if (keys_.count(full)) fail("'" + key + "' is given twice in [" + section_ + "] (first at line " + std::to_string(keys_[full]) + ")");
    keys_[full] = line_;
    FormulaText f;
    f.text = value;
    f.where.source = d_.origin.source;
    f.where.line = line_;
    f.where.column = static_cast<int>(vstart) + 1;
    entry(key, f, comment);
  }

  template <class V>
  void put(std::vector<V>& v, int index, const V& x) {
    if (static_cast<int>(v.size()) < index) v.resize(static_cast<std::size_t>(index));
    v[static_cast<std::size_t>(index - 1)] = x;
  }

  void entry(const std::string& key, const FormulaText& f, const std::string& comment) {
    int i = 0;
    if (section_ == "system") {
      if (key == "name") {
        d_.name = f.text;
      } else if (key == "description") {
        d_.description = f.text;
      } else if (key == "coordinates") {
        int n = 0;
        try {
          std::size_t used = 0;
          n = std::stoi(f.text, &used);
          if (used != f.text.size()) n = 0;
        } catch (const std::exception&) {
          n = 0;
        }
        if (n <= 0) fail("coordinates must be a positive integer, got '" + f.text + "'", f.where.column);
        d_.coordinates = n;
      } else if (key == "time_transform") {
        d_.time_transform = f;
      } else {
        fail("unknown key '" + key + "' in [system] (keys: name, description, coordinates, time_transform)");
      }
    } else if (section_ == "parameters") {
      if (is_program_option_name(key))
        fail("parameter '" + key + "' has the name of a program option (--" + key +
             "): as an option of its own it would take that option's place; rename it");
      d_.parameters.push_back({key, f, comment});
    } else if (section_ == "definitions") {
      d_.definitions.push_back({key, f});
    } else if (section_ == "dynamics") {
      if (key == "L")
        d_.lagrangian = f;
      else if (key == "herglotz")
        d_.herglotz = f;
      else if (key == "E")
        d_.energy = f;
      else if (indexed(key, "F", i))
        put(force_, i, Slot{f, line_});
      else
        fail("unknown key '" + key + "' in [dynamics] (keys: L, herglotz, E, F1, F2, ...)");
    } else if (section_ == "constraints") {
      if (indexed(key, "phi", i))
        put(phi_, i, Slot{f, line_});
      else if (indexed(key, "g", i))
        put(g_, i, Slot{f, line_});
      else
        fail("unknown key '" + key + "' in [constraints] (phi1, phi2, ...: rows linear in the velocities; g1, g2, ...: holonomic)");
    } else if (section_ == "initial") {
      if (indexed(key, "q", i))
        put(q0_, i, Slot{f, line_});
      else if (indexed(key, "v", i))
        put(v0_, i, Slot{f, line_});
      else if (key == "t0")
        d_.initial_t = f;
      else if (key == "z0")
        d_.initial_z = f;
      else
        fail("unknown key '" + key + "' in [initial] (keys: q1, q2, ..., v1, v2, ..., t0, z0)");
    } else if (section_ == "exact") {
      if (indexed(key, "q", i))
        put(xq_, i, Slot{f, line_});
      else if (indexed(key, "v", i))
        put(xv_, i, Slot{f, line_});
      else
        fail("unknown key '" + key + "' in [exact] (keys: q1, q2, ... as formulas in t; optionally v1, v2, ...)");
    }
  }

  struct Slot {
    FormulaText f;
    int line = 0;
  };

  // Rows 1..k, each given once, none beyond `limit`.
  std::vector<FormulaText> rows(const std::vector<Slot>& v, const std::string& prefix, int limit, const std::string& why) {
    std::vector<FormulaText> out;
    for (std::size_t k = 0; k < v.size(); ++k) {
      if (v[k].line == 0) {
        line_ = v.back().line;
        fail(prefix + std::to_string(v.size()) + " is given but " + prefix + std::to_string(k + 1) + " is not");
      }
      if (static_cast<int>(k) + 1 > limit) {
        line_ = v[k].line;
        fail(prefix + std::to_string(k + 1) + ": " + why);
      }
      out.push_back(v[k].f);
    }
    return out;
  }

  void finish() {
    line_ = 0;
    auto whole = [&](const std::string& what) { throw InputError(d_.origin.source + ": " + what); };
    if (!seen_sections_.count("system")) whole("no [system] section (it gives name and coordinates)");
    if (d_.name.empty()) whole("[system] has no name");
    if (d_.coordinates == 0) whole("[system] has no 'coordinates = n'");
    const int n = d_.coordinates;
    const std::string dims = "the system has " + std::to_string(n) + " coordinate" + (n == 1 ? "" : "s");
    d_.force = rows(force_, "F", n, dims);
    if (!d_.force.empty() && static_cast<int>(d_.force.size()) != n) {
      line_ = force_.back().line;
      fail("F" + std::to_string(force_.size()) + " is the last force component but " + dims + ": give F1..F" +
           std::to_string(n) + " (0 where there is none)");
    }
    if (!phi_.empty() && !g_.empty()) {
      line_ = std::max(phi_.back().line, g_.back().line);
      fail("constraints mix phi (linear in the velocities) and g (holonomic) rows: use one kind");
    }
    if (!g_.empty()) {
      d_.constraint_kind = ConstraintKind::holonomic;
      d_.constraints = rows(g_, "g", n, dims);
    } else {
      d_.constraints = rows(phi_, "phi", n, dims);
    }
    d_.initial_q = rows(q0_, "q", n, dims);
    d_.initial_v = rows(v0_, "v", n, dims);
    for (int i = 0; i < n; ++i) {
      if (static_cast<std::size_t>(i) >= d_.initial_q.size())
        whole("[initial] has no q" + std::to_string(i + 1) + " (give q1..q" + std::to_string(n) + " and v1..v" + std::to_string(n) + ")");
      if (static_cast<std::size_t>(i) >= d_.initial_v.size())
        whole("[initial] has no v" + std::to_string(i + 1) + " (give q1..q" + std::to_string(n) + " and v1..v" + std::to_string(n) + ")");
    }
    if (!d_.lagrangian.given()) whole("[dynamics] has no Lagrangian 'L = ...'");
    d_.exact_q = rows(xq_, "q", n, dims);
    d_.exact_v = rows(xv_, "v", n, dims);
    if (!xv_.empty() && xq_.empty()) {
      line_ = xv_.front().line;
      fail("[exact] gives velocities but no positions: give q1..q" + std::to_string(n));
    }
    if (!xq_.empty() && static_cast<int>(d_.exact_q.size()) != n) {
      line_ = xq_.back().line;
      fail("[exact] gives q1..q" + std::to_string(d_.exact_q.size()) + " but " + dims + ": give q1..q" + std::to_string(n));
    }
    if (!xv_.empty() && static_cast<int>(d_.exact_v.size()) != n) {
      line_ = xv_.back().line;
      fail("[exact] gives v1..v" + std::to_string(d_.exact_v.size()) + " but " + dims +
           ": give v1..v" + std::to_string(n) + ", or none (they are then the derivatives of the q's)");
    }
  }

  SystemDescription d_;
  int line_ = 0;
  std::string section_;
  std::map<std::string, int> seen_sections_, keys_;
  std::vector<Slot> force_, phi_, g_, q0_, v0_, xq_, xv_;
};

}  // namespace

SystemDescription parse_system_file(const std::string& text, const std::string& source) {
  return Reader(source).run(text);
}

SystemDescription read_system_file(const std::filesystem::path& path) {
  // An unset shell variable ("--system-file $F") must not read as "no file".
  require(!path.empty(), "the system file's path is empty");
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  require(!ec && std::filesystem::exists(status), "cannot read system file '" + path.string() + "': no such file");
  require(std::filesystem::is_regular_file(status), "cannot read system file '" + path.string() + "': not a regular file");
  const auto size = std::filesystem::file_size(path, ec);
  require(!ec, "cannot read system file '" + path.string() + "': " + ec.message());
  require(size <= max_system_file_bytes, "system file '" + path.string() + "' is larger than " +
                                             std::to_string(max_system_file_bytes) + " bytes: not a formula file?");
  std::ifstream in(path, std::ios::binary);
  require(static_cast<bool>(in), "cannot read system file '" + path.string() + "'");
  std::stringstream ss;
  ss << in.rdbuf();
  require(!in.bad(), "cannot read system file '" + path.string() + "': read error");
  return parse_system_file(ss.str(), path.string());
}

}  // namespace geomint::formula
