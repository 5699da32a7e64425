#include "experiments/compare/FlipMetric.h"

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <sstream>

#include <unistd.h>

#include "experiments/output/PlotScript.h"

namespace experiments {

namespace fs = std::filesystem;

namespace {

constexpr const char* kScript = "flip.py";
// flip.py's exit statuses (see its docstring).
constexpr int kNumpyMissing = 3;
constexpr int kPackageMissing = 4;

// A private temporary folder, removed with everything in it when this goes out of scope.
class TemporaryFolder {
public:
    TemporaryFolder() {
        std::string pattern = (fs::temp_directory_path() / "testbed-flip-XXXXXX").string();
        if (!mkdtemp(pattern.data()))
            throw std::runtime_error("cannot create a temporary folder for ꟻLIP in " +
                                     fs::temp_directory_path().string());
        mPath = pattern;
    }
    ~TemporaryFolder() {
        std::error_code ignored;
        fs::remove_all(mPath, ignored);
    }
    TemporaryFolder(const TemporaryFolder&) = delete;
    TemporaryFolder& operator=(const TemporaryFolder&) = delete;
    const fs::path& path() const { return mPath; }

private:
    fs::path mPath;
};

std::string readFile(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
}

// The script's last non-empty output line (its reason), without the "flip.py: " prefix.
std::string lastLine(const fs::path& log) {
    std::istringstream lines(readFile(log));
    std::string line, last;
    while (std::getline(lines, line))
        if (!line.empty())
            last = line;
    const std::string prefix = "flip.py: ";
    return last.rfind(prefix, 0) == 0 ? last.substr(prefix.size()) : last;
}

std::string checkPython(const std::string& python) {
    const std::string getIt = std::string("run ./run.sh (it makes .venv/ and installs "
                                          "flip-evaluator==") +
                              kFlipEvaluatorVersion + "), or set " + kFlipPythonVariable +
                              " to a Python that has the package";
    if (python.find('/') != std::string::npos && access(python.c_str(), X_OK) != 0)
        return "no Python at " + python + "; " + getIt;
    const fs::path script = plotScriptPath(kScript);
    if (!fs::is_regular_file(script))
        return "the script " + script.string() + " is missing";
    TemporaryFolder folder;
    const fs::path log = folder.path() / "check.log";
    const int status = runProcessLogged(
        {python, script.string(), "check", "--out", (folder.path() / "check.json").string()}, log);
    if (status == 0)
        return "";
    if (status == kPackageMissing)
        return "the Python package flip-evaluator is not installed in " + python + "; " + getIt;
    if (status == kNumpyMissing)
        return lastLine(log);
    if (status == 127)
        return "cannot run " + python + "; " + getIt;
    return "'" + python + " " + script.string() + " check' failed (exit status " +
           std::to_string(status) + "): " + lastLine(log);
}

// Every value of the three planes is finite: ꟻLIP is undefined otherwise.
size_t nonFiniteCount(const lighting::StageResult& image) {
    size_t count = 0;
    for (const std::vector<float>& plane : image.radiance)
        for (float v : plane)
            count += std::isfinite(v) ? 0 : 1;
    return count;
}

void writeInterleaved(const fs::path& path, const lighting::StageResult& image) {
    const size_t pixels = size_t(image.width) * image.height;
    std::vector<float> rgb(pixels * 3);
    for (size_t i = 0; i < pixels; ++i)
        for (int c = 0; c < 3; ++c)
            rgb[3 * i + size_t(c)] = image.radiance[c][i];
    std::ofstream out(path, std::ios::binary);
    out.write(reinterpret_cast<const char*>(rgb.data()), std::streamsize(rgb.size() * 4));
    if (!out)
        throw std::runtime_error("cannot write " + path.string());
}

FlipResult unavailable(std::string reason) {
    FlipResult result;
    result.unavailableReason = std::move(reason);
    return result;
}

} // namespace

std::string flipPython() {
    if (const char* requested = std::getenv(kFlipPythonVariable); requested && *requested)
        return requested;
    return (sourceDirectory() / ".venv" / "bin" / "python3").string();
}

std::string flipUnavailableReason() {
    static std::mutex mutex;
    static std::map<std::string, std::string> checked; // by Python
    const std::string python = flipPython();
    const std::lock_guard<std::mutex> lock(mutex);
    const auto it = checked.find(python);
    if (it != checked.end())
        return it->second;
    return checked[python] = checkPython(python);
}

FlipResult computeFlip(const lighting::StageResult& test, const lighting::StageResult& reference) {
    if (test.width != reference.width || test.height != reference.height)
        return unavailable("the images differ in size");
    if (const std::string reason = flipUnavailableReason(); !reason.empty())
        return unavailable(reason);
    if (const size_t bad = nonFiniteCount(test))
        return unavailable("the render holds " + std::to_string(bad) +
                           " non-finite values (NaN or infinity); ꟻLIP needs finite ones");
    if (const size_t bad = nonFiniteCount(reference))
        return unavailable("the reference holds " + std::to_string(bad) +
                           " non-finite values (NaN or infinity); ꟻLIP needs finite ones");
    try {
        TemporaryFolder folder;
        const fs::path& dir = folder.path();
        writeInterleaved(dir / "reference.f32", reference);
        writeInterleaved(dir / "test.f32", test);
        const std::string python = flipPython(), script = plotScriptPath(kScript).string();
        const int status = runProcessLogged(
            {python, script, "evaluate", "--reference", (dir / "reference.f32").string(), "--test",
             (dir / "test.f32").string(), "--width", std::to_string(test.width), "--height",
             std::to_string(test.height), "--map", (dir / "map.f32").string(), "--out",
             (dir / "flip.json").string()},
            dir / "evaluate.log");
        if (status != 0)
            return unavailable("'" + python + " " + script + " evaluate' failed (exit status " +
                               std::to_string(status) + "): " + lastLine(dir / "evaluate.log"));
        const nlohmann::json output = nlohmann::json::parse(readFile(dir / "flip.json"));
        const std::string map = readFile(dir / "map.f32");
        const size_t pixels = size_t(test.width) * test.height;
        if (map.size() != pixels * sizeof(float))
            return unavailable("flip.py wrote a map of " + std::to_string(map.size()) +
                               " bytes, expected " + std::to_string(pixels * sizeof(float)));
        FlipResult result;
        result.mean = output.at("mean").get<double>();
        result.errorMap.resize(pixels);
        std::memcpy(result.errorMap.data(), map.data(), map.size());
        result.parameters = output.value("parameters", nlohmann::json::object());
        result.parameters["version"] = output.value("version", "unknown");
        result.parameters["mode"] = "HDR";
        return result;
    } catch (const std::exception& e) {
        return unavailable(std::string("ꟻLIP failed: ") + e.what());
    }
}

ScalarMapStyle flipMapStyle() {
    ScalarMapStyle style;
    style.max = 1.0f;
    style.colourMap = "magma";
    style.title = "HDR-FLIP error (flip-evaluator), 0..1";
    return style;
}

} // namespace experiments
