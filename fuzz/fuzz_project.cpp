// Project JSON loader and `--set`: the first line of the input is one override, the rest the
// project document. The document is read as loadProject reads a file (sceneFromJson); the
// override is applied as the command line applies it, to the document of the scene that loaded
// (or the defaults), and read again. Our refusals are ProjectError; a scene that loads must
// survive sceneToJson -> text -> sceneFromJson unchanged.

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "FuzzSupport.h"
#include "Project.h"

using namespace terralux;
using json = nlohmann::json;

namespace {

// The scene survives its own JSON: what the writer produces, the reader takes back unchanged.
void checkRoundTrip(const SceneDescription& scene) {
    const json doc = sceneToJson(scene);
    std::vector<std::string> warnings;
    const SceneDescription back = sceneFromJson(json::parse(doc.dump()), "round trip", &warnings);
    FUZZ_CHECK(sceneToJson(back) == doc);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string input(reinterpret_cast<const char*>(data), size);
    const size_t eol = input.find('\n');
    const std::string assignment = input.substr(0, eol);
    const std::string text = eol == std::string::npos ? std::string() : input.substr(eol + 1);

    json base = defaultProjectJson();
    const json doc = json::parse(text, nullptr, false);
    if (!doc.is_discarded()) {
        std::vector<std::string> warnings;
        try {
            const SceneDescription scene = sceneFromJson(doc, "fuzz.terralux.json", &warnings);
            checkRoundTrip(scene);
            base = sceneToJson(scene);
        } catch (const ProjectError&) {
        }
    }
    try {
        applyOverride(base, assignment);
        std::vector<std::string> warnings;
        checkRoundTrip(sceneFromJson(base, "--set", &warnings));
    } catch (const ProjectError&) {
    }
    return 0;
}
