#include "lumigauss/viewer/standalone_page.h"

#include <nlohmann/json.hpp>

#include <cctype>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <vector>

#include "lumigauss/util/base64.h"
#include "lumigauss/util/error.h"
#include "lumigauss/viewer/viewer_assets.h"

namespace lumigauss::view {
namespace {

constexpr std::string_view kModuleScriptTag = R"(<script type="module" src="viewer.js"></script>)";

std::string_view asset_text(std::string_view name) {
    const EmbeddedAsset* asset = find_viewer_asset(name);
    if (!asset) throw Error("viewer page: no embedded asset '" + std::string(name) + "'");
    return asset->bytes;
}

// "sh.js" -> "__lg_sh_js": the name of the constant holding a module's exports.
std::string module_variable(const std::string& file) {
    std::string v = "__lg_";
    for (char c : file) v += (std::isalnum(static_cast<unsigned char>(c)) ? c : '_');
    return v;
}

struct Module {
    std::vector<std::string> imports;  // files this one imports, in order
    std::vector<std::string> exports;  // names it exports
    std::string body;                  // the source with imports rewritten and `export ` removed
};

Module translate_module(const std::string& file) {
    static const std::regex import_line(R"(^import \{([^}]*)\} from '\./([A-Za-z0-9_]+\.js)';\s*$)");
    static const std::regex export_line(
        R"(^export (const|let|function|async function|class) ([A-Za-z_$][A-Za-z0-9_$]*))");
    static const std::regex other_module_syntax(R"(^\s*(import|export)\b)");
    Module m;
    std::istringstream in{std::string(asset_text(file))};
    std::ostringstream body;
    int number = 0;
    for (std::string line; std::getline(in, line);) {
        ++number;
        std::smatch match;
        if (std::regex_match(line, match, import_line) && match[1].str().find(" as ") == std::string::npos) {
            m.imports.push_back(match[2]);
            body << "const {" << match[1].str() << "} = " << module_variable(match[2]) << ";\n";
        } else if (std::regex_search(line, match, export_line)) {
            m.exports.push_back(match[2]);
            body << line.substr(7) << '\n';  // without "export "
        } else if (std::regex_search(line, other_module_syntax)) {
            throw Error("viewer page: " + file + " line " + std::to_string(number) +
                        " has module syntax the bundler does not handle: " + line);
        } else {
            body << line << '\n';
        }
    }
    m.body = body.str();
    return m;
}

// Depth first: every module after the modules it imports.
void add_in_order(const std::string& file, std::map<std::string, Module>& modules,
                  std::set<std::string>& open, std::vector<std::string>& order) {
    if (modules.count(file)) return;
    if (!open.insert(file).second)
        throw Error("viewer page: modules import each other in a cycle at " + file);
    Module m = translate_module(file);
    for (const std::string& dep : m.imports) add_in_order(dep, modules, open, order);
    modules.emplace(file, std::move(m));
    order.push_back(file);
}

// Text that sits inside a <script> element: "</script" or "<!--" there would end or confuse it.
void check_script_safe(const std::string& text, const std::string& what) {
    std::string lower(text);
    for (char& c : lower) c = char(std::tolower(static_cast<unsigned char>(c)));  // </SCRIPT ends it too
    if (lower.find("</script") != std::string::npos || lower.find("<!--") != std::string::npos)
        throw Error("viewer page: " + what + " holds '</script' or '<!--'");
}

// A JSON text made safe inside <script>: '<' only occurs in JSON strings, where \u003c means the same.
std::string script_safe_json(std::string_view json) {
    std::string out;
    out.reserve(json.size());
    for (char c : json) {
        if (c == '<')
            out += "\\u003c";
        else
            out += c;
    }
    return out;
}

}  // namespace

std::string bundle_viewer_modules(std::string_view entry) {
    std::map<std::string, Module> modules;
    std::set<std::string> open;
    std::vector<std::string> order;
    add_in_order(std::string(entry), modules, open, order);
    std::ostringstream out;
    for (const std::string& file : order) {
        const Module& m = modules.at(file);
        out << "// ---- " << file << "\nconst " << module_variable(file) << " = (() => {\n" << m.body;
        out << "return {";
        for (std::size_t k = 0; k < m.exports.size(); ++k) out << (k ? ", " : " ") << m.exports[k];
        out << " };\n})();\n";
    }
    return out.str();
}

std::string standalone_viewer_page(std::string_view model_payload, std::string_view scene_json) {
    std::string page(asset_text("index.html"));
    const std::size_t tag = page.find(kModuleScriptTag);
    if (tag == std::string::npos)
        throw Error("viewer page: index.html does not load viewer.js as expected: " +
                    std::string(kModuleScriptTag));
    const std::string bundle = bundle_viewer_modules("viewer.js");
    check_script_safe(bundle, "the bundled modules");
    const std::string worker = nlohmann::json(std::string(asset_text("sort_worker.js"))).dump();
    std::string data = "<script>\nwindow.__lgEmbedded = {\n  scene: " + script_safe_json(scene_json) +
                       ",\n  sortWorker: " + script_safe_json(worker) + ",\n  model: \"" +
                       base64_encode(model_payload) + "\"\n};\n</script>\n";
    std::string script = "<script type=\"module\">\n" + bundle + "</script>";
    page.replace(tag, kModuleScriptTag.size(), data + script);
    return page;
}

}  // namespace lumigauss::view
