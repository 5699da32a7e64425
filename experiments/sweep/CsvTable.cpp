#include "experiments/sweep/CsvTable.h"

#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace experiments {

namespace {

std::string field(const std::string& text) {
    const bool quote = text.find_first_of(",\"\r\n") != std::string::npos ||
                       (!text.empty() && (text.front() == ' ' || text.back() == ' '));
    if (!quote)
        return text;
    std::string quoted = "\"";
    for (char c : text)
        quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
    return quoted + "\"";
}

void appendLine(std::string& csv, const std::vector<std::string>& cells) {
    for (size_t c = 0; c < cells.size(); ++c) {
        if (c)
            csv += ',';
        csv += field(cells[c]);
    }
    csv += "\n";
}

} // namespace

CsvTable::CsvTable(std::vector<std::string> header) : mHeader(std::move(header)) {}

void CsvTable::addRow(std::vector<std::string> cells) {
    if (cells.size() != mHeader.size())
        throw std::invalid_argument("CSV row of " + std::to_string(cells.size()) + " cells for " +
                                    std::to_string(mHeader.size()) + " columns");
    mRows.push_back(std::move(cells));
}

std::string CsvTable::text() const {
    std::string csv;
    appendLine(csv, mHeader);
    for (const std::vector<std::string>& row : mRows)
        appendLine(csv, row);
    return csv;
}

std::string csvNumber(double value) {
    if (std::isnan(value))
        return "nan";
    char text[32];
    std::snprintf(text, sizeof text, "%.9g", value);
    return text;
}

} // namespace experiments
