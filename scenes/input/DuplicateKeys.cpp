// DuplicateKeys.h: a SAX handler that keeps, for each open object, the keys seen so far and the
// path to it, and stops the parse at the first repeat.
#include "scenes/input/DuplicateKeys.h"

#include <set>
#include <vector>

#include <nlohmann/json.hpp>

namespace scenes {

namespace {

using Json = nlohmann::json;

class DuplicateKeyFinder : public nlohmann::json_sax<Json> {
public:
    std::string duplicate;

    bool null() override { return value(); }
    bool boolean(bool) override { return value(); }
    bool number_integer(number_integer_t) override { return value(); }
    bool number_unsigned(number_unsigned_t) override { return value(); }
    bool number_float(number_float_t, const string_t&) override { return value(); }
    bool string(string_t&) override { return value(); }
    bool binary(binary_t&) override { return value(); }
    bool start_object(std::size_t) override { return open(true); }
    bool start_array(std::size_t) override { return open(false); }
    bool end_object() override { return close(); }
    bool end_array() override { return close(); }
    bool key(string_t& key) override {
        Frame& frame = mFrames.back();
        if (!frame.keys.insert(key).second) {
            duplicate = join(frame.path, key);
            return false; // stops the parse: one duplicate is enough to refuse the file
        }
        frame.lastKey = key;
        return true;
    }
    bool parse_error(std::size_t, const std::string&, const nlohmann::detail::exception&) override {
        return false; // the reader's own parse reports it
    }

private:
    struct Frame {
        bool isObject;
        std::string path;
        std::set<std::string> keys; // objects only
        std::string lastKey;        // objects: the key of the value being read
        size_t nextIndex = 0;       // arrays: the index of the next element
    };
    std::vector<Frame> mFrames;

    static std::string join(const std::string& parent, const std::string& key) {
        return parent.empty() ? key : parent + "." + key;
    }

    // A scalar counts as an element of an enclosing array.
    bool value() {
        if (!mFrames.empty() && !mFrames.back().isObject)
            ++mFrames.back().nextIndex;
        return true;
    }

    bool open(bool isObject) {
        std::string path;
        if (!mFrames.empty()) {
            Frame& parent = mFrames.back();
            path = parent.isObject ? join(parent.path, parent.lastKey)
                                   : parent.path + "[" + std::to_string(parent.nextIndex++) + "]";
        }
        mFrames.push_back({isObject, std::move(path), {}, {}, 0});
        return true;
    }

    bool close() {
        mFrames.pop_back();
        return true;
    }
};

} // namespace

std::string jsonDuplicateKey(std::string_view text) {
    DuplicateKeyFinder finder;
    try {
        Json::sax_parse(text, &finder);
    } catch (const std::exception&) {
        // Malformed input the parser reports by exception: the reader's parse will say so.
    }
    return finder.duplicate;
}

std::string jsonDuplicateKeyProblem(std::string_view text) {
    const std::string key = jsonDuplicateKey(text);
    return key.empty() ? "" : "key '" + key + "' is given twice in the same object";
}

} // namespace scenes
