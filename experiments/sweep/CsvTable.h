// CsvTable: the one CSV writer of the testbed: a sweep's results.csv (ResultsTable.h) and the
// studies' normals.csv, depth.csv and depth_steps.csv (experiments/studies/). RFC 4180: fields
// separated by commas, one line per row ending in "\n", a field quoted (inner quotes doubled) when
// it holds a comma, a quote or a line break or begins or ends with a space; an empty field is an
// empty string or a missing value. Callers turn values into text (numbers with csvNumber, or as
// their JSON does) so a column reads the same in every file.
// Thread safety: a value; no shared state.
#pragma once

#include <string>
#include <vector>

namespace experiments {

class CsvTable {
public:
    explicit CsvTable(std::vector<std::string> header);

    // Throws std::invalid_argument when the row has not one cell per header column.
    void addRow(std::vector<std::string> cells);
    // The header line and every row.
    std::string text() const;

private:
    std::vector<std::string> mHeader;
    std::vector<std::vector<std::string>> mRows;
};

// A number as the studies' CSVs write it: 9 significant digits (%.9g: every float exactly,
// doubles to 1e-9 relative), "nan" for NaN, "inf" / "-inf".
std::string csvNumber(double value);

} // namespace experiments
