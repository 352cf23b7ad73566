// The CSV files of the tools, written row by row: the header names the columns, each value is
// streamed into the next cell, and a row with more or fewer cells than the header is a bug
// (std::logic_error) rather than a shifted column in a committed result.
#pragma once

#include <cstddef>
#include <fstream>
#include <ios>
#include <stdexcept>
#include <string>

namespace cube_scan_matcher::tools {

/// A value written with every significant digit (17), so that results compare bit for bit.
struct Exact {
  double value;
};

class CsvWriter {
 public:
  enum class Mode { Truncate, Append };

  /// Opens `path` (std::runtime_error "PATH: cannot write") and writes `header`, the column
  /// names separated by commas. Append adds rows to an existing file, whose header is taken as
  /// this one (it is written only when the file is new).
  CsvWriter(const std::string& path, const std::string& header, Mode mode = Mode::Truncate)
      : path_(path) {
    const bool fresh = mode == Mode::Truncate || !std::ifstream(path).good();
    out_.open(path, mode == Mode::Append ? std::ios::app : std::ios::trunc);
    if (!out_) throw std::runtime_error(path + ": cannot write");
    columns_ = 1;
    for (char c : header) columns_ += c == ',';
    if (fresh) out_ << header << '\n';
  }

  /// The next cell of the current row.
  template <class T>
  CsvWriter& operator<<(const T& value) {
    if (cells_++ > 0) out_ << ',';
    out_ << value;
    return *this;
  }
  CsvWriter& operator<<(Exact e) {
    if (cells_++ > 0) out_ << ',';
    const std::streamsize before = out_.precision(17);
    out_ << e.value;
    out_.precision(before);
    return *this;
  }

  /// Ends the current row: it must have as many cells as the header has columns.
  void endRow() {
    if (cells_ != columns_)
      throw std::logic_error(path_ + ": a row of " + std::to_string(cells_) + " cells under " +
                             std::to_string(columns_) + " columns");
    out_ << '\n';
    cells_ = 0;
  }

 private:
  std::string path_;
  std::ofstream out_;
  std::size_t columns_ = 0, cells_ = 0;
};

}  // namespace cube_scan_matcher::tools
