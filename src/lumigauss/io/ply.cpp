#include "lumigauss/io/ply.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <sstream>

#include "lumigauss/io/atomic_file.h"
#include "lumigauss/util/error.h"

namespace lumigauss {
namespace {

enum class PlyFormat { Ascii, BinaryLittle, BinaryBig };

struct PlyProperty {
    std::string name;
    std::string type;       // scalar type, or the item type of a list
    std::string list_size;  // empty unless a list property
};

struct PlyElement {
    std::string name;
    std::size_t count = 0;
    std::vector<PlyProperty> properties;
};

int type_size(const std::string& type, const std::string& file) {
    if (type == "char" || type == "uchar" || type == "int8" || type == "uint8") return 1;
    if (type == "short" || type == "ushort" || type == "int16" || type == "uint16") return 2;
    if (type == "int" || type == "uint" || type == "int32" || type == "uint32" || type == "float" ||
        type == "float32")
        return 4;
    if (type == "double" || type == "float64") return 8;
    fail_in_file(file, "unknown PLY property type '" + type + "'");
}

template <typename T>
T load_swapped(const unsigned char* p, bool swap) {
    unsigned char b[sizeof(T)];
    std::memcpy(b, p, sizeof(T));
    if (swap) std::reverse(b, b + sizeof(T));
    T v;
    std::memcpy(&v, b, sizeof(T));
    return v;
}

double decode(const std::string& type, const unsigned char* p, bool swap) {
    if (type == "char" || type == "int8") return load_swapped<std::int8_t>(p, swap);
    if (type == "uchar" || type == "uint8") return load_swapped<std::uint8_t>(p, swap);
    if (type == "short" || type == "int16") return load_swapped<std::int16_t>(p, swap);
    if (type == "ushort" || type == "uint16") return load_swapped<std::uint16_t>(p, swap);
    if (type == "int" || type == "int32") return load_swapped<std::int32_t>(p, swap);
    if (type == "uint" || type == "uint32") return load_swapped<std::uint32_t>(p, swap);
    if (type == "float" || type == "float32") return load_swapped<float>(p, swap);
    return load_swapped<double>(p, swap);
}

struct PlyHeader {
    PlyFormat format = PlyFormat::Ascii;
    std::vector<PlyElement> elements;
};

PlyHeader parse_header(std::istream& in, const std::string& path) {
    std::string line;
    if (!std::getline(in, line) || line.substr(0, 3) != "ply")
        fail_in_file(path, "not a PLY file (no 'ply' magic)");
    PlyHeader h;
    bool have_format = false;
    int line_no = 1;
    while (std::getline(in, line)) {
        ++line_no;
        if (!line.empty() && line.back() == '\r') line.pop_back();
        std::istringstream ls(line);
        std::string word;
        ls >> word;
        const std::string where = "header line " + std::to_string(line_no) + ": ";
        if (word == "end_header") {
            if (!have_format) fail_in_file(path, "PLY header has no 'format' line");
            return h;
        }
        if (word == "format") {
            std::string f;
            ls >> f;
            if (f == "ascii")
                h.format = PlyFormat::Ascii;
            else if (f == "binary_little_endian")
                h.format = PlyFormat::BinaryLittle;
            else if (f == "binary_big_endian")
                h.format = PlyFormat::BinaryBig;
            else
                fail_in_file(path, where + "unknown PLY format '" + f + "'");
            have_format = true;
        } else if (word == "element") {
            PlyElement e;
            long long count = -1;
            ls >> e.name >> count;
            if (!ls || count < 0) fail_in_file(path, where + "malformed element line '" + line + "'");
            e.count = std::size_t(count);
            h.elements.push_back(e);
        } else if (word == "property") {
            if (h.elements.empty()) fail_in_file(path, where + "property before any element");
            PlyProperty p;
            std::string t;
            ls >> t;
            if (t == "list")
                ls >> p.list_size >> p.type >> p.name;
            else
                p.type = t, ls >> p.name;
            if (!ls) fail_in_file(path, where + "malformed property line '" + line + "'");
            type_size(p.type, path);
            if (!p.list_size.empty()) type_size(p.list_size, path);
            for (const PlyProperty& other : h.elements.back().properties)
                if (other.name == p.name)  // which of the two columns would a reader take?
                    fail_in_file(path, where + "property '" + p.name + "' of element '" +
                                           h.elements.back().name + "' is declared twice");
            h.elements.back().properties.push_back(p);
        } else if (word != "comment" && word != "obj_info" && !word.empty()) {
            fail_in_file(path, where + "unexpected '" + word + "'");
        }
    }
    fail_in_file(path, "PLY header ends before 'end_header'");
}

// Reads one element's records. Vertex values go to `table`; other elements are consumed and dropped.
void read_element_binary(std::istream& in, const PlyElement& e, bool swap, PlyVertexTable* table,
                         const std::string& path) {
    // Records of no property hold no bytes: there is nothing to read, and counting through 10^15 of them
    // hung the reader (found by libFuzzer).
    if (e.properties.empty()) return;
    const bool has_list = std::any_of(e.properties.begin(), e.properties.end(),
                                      [](const PlyProperty& p) { return !p.list_size.empty(); });
    if (has_list && table) fail_in_file(path, "list properties in the vertex element are not supported");
    std::size_t record = 0;
    for (const auto& p : e.properties) record += std::size_t(type_size(p.type, path));
    std::vector<unsigned char> buf(has_list ? 8 : record);
    for (std::size_t i = 0; i < e.count; ++i) {
        if (has_list) {
            for (const auto& p : e.properties) {
                const int size = type_size(p.list_size.empty() ? p.type : p.list_size, path);
                if (!in.read(reinterpret_cast<char*>(buf.data()), size)) break;
                if (p.list_size.empty()) continue;
                const auto n = std::size_t(decode(p.list_size, buf.data(), swap));
                in.ignore(std::streamsize(n * std::size_t(type_size(p.type, path))));
            }
        } else {
            if (!in.read(reinterpret_cast<char*>(buf.data()), std::streamsize(record))) break;
            if (!table) continue;
            std::size_t off = 0;
            for (std::size_t k = 0; k < e.properties.size(); ++k) {
                table->columns[k][i] = float(decode(e.properties[k].type, buf.data() + off, swap));
                off += std::size_t(type_size(e.properties[k].type, path));
            }
        }
        if (!in)
            fail_in_file(path, "truncated: element '" + e.name + "' ends at record " + std::to_string(i));
    }
    if (!in)
        fail_in_file(path,
                     "truncated: element '" + e.name + "' promises " + std::to_string(e.count) + " records");
}

void read_element_ascii(std::istream& in, const PlyElement& e, PlyVertexTable* table,
                        const std::string& path) {
    std::string line;
    for (std::size_t i = 0; i < e.count; ++i) {
        if (!std::getline(in, line))
            fail_in_file(
                path, "truncated: element '" + e.name + "' promises " + std::to_string(e.count) + " records");
        if (!table) continue;
        std::istringstream ls(line);
        for (std::size_t k = 0; k < e.properties.size(); ++k) {
            double v;
            if (!(ls >> v))
                fail_in_file(path, "element '" + e.name + "' record " + std::to_string(i) + ": expected " +
                                       std::to_string(e.properties.size()) + " numbers");
            table->columns[k][i] = float(v);
        }
    }
}

// The bytes of the file after its header.
std::uint64_t bytes_after_header(std::istream& in, const std::string& path) {
    const std::streampos here = in.tellg();
    in.seekg(0, std::ios::end);
    const std::streampos end = in.tellg();
    in.seekg(here);
    if (here < 0 || end < here || !in) fail_in_file(path, "cannot measure the PLY file");
    return std::uint64_t(end - here);
}

// A declared record count must fit in the bytes that follow the header (a 700-byte file must not make the
// reader allocate for 20 million vertices): binary records have a fixed size, ASCII ones take at least two
// bytes per property (a digit and a separator).
void check_declared_count(const PlyElement& e, PlyFormat format, std::uint64_t data_bytes,
                          const std::string& path) {
    std::uint64_t record = 0;
    for (const auto& p : e.properties)
        record += format == PlyFormat::Ascii ? 2 : std::uint64_t(type_size(p.type, path));
    if (record == 0 || e.count <= data_bytes / record) return;
    fail_in_file(path, "truncated, or a wrong count: declares " + std::to_string(e.count) + " '" + e.name +
                           "' records of at least " + std::to_string(record) + " bytes, but only " +
                           std::to_string(data_bytes) + " bytes follow the header");
}

}  // namespace

bool PlyVertexTable::has(const std::string& name) const {
    return std::find(names.begin(), names.end(), name) != names.end();
}

const std::vector<float>& PlyVertexTable::column(const std::string& name, const std::string& file) const {
    const auto it = std::find(names.begin(), names.end(), name);
    if (it == names.end()) fail_in_file(file, "PLY vertex property '" + name + "' is missing");
    return columns[std::size_t(it - names.begin())];
}

void PlyVertexTable::add(const std::string& name, std::vector<float> values) {
    if (names.empty()) count = values.size();
    if (values.size() != count) throw Error("PLY column '" + name + "' has the wrong length");
    names.push_back(name);
    columns.push_back(std::move(values));
}

PlyVertexTable read_ply_vertices(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) fail_in_file(path, "cannot open PLY file");
    const PlyHeader h = parse_header(in, path);
    const std::uint64_t data_bytes = bytes_after_header(in, path);
    const bool swap = (h.format == PlyFormat::BinaryBig) == (std::endian::native == std::endian::little);
    PlyVertexTable table;
    bool found = false;
    for (const PlyElement& e : h.elements) {
        PlyVertexTable* target = nullptr;
        if (e.name == "vertex" && !found) {
            found = true;
            check_declared_count(e, h.format, data_bytes, path);  // before allocating for it
            table.count = e.count;
            for (const auto& p : e.properties) {
                table.names.push_back(p.name);
                table.columns.emplace_back(e.count);
            }
            target = &table;
        }
        if (h.format == PlyFormat::Ascii)
            read_element_ascii(in, e, target, path);
        else
            read_element_binary(in, e, swap, target, path);
    }
    if (!found) fail_in_file(path, "PLY file has no 'vertex' element");
    // Binary data past the last declared record: the counts undercount what the file holds (a wrong count, or
    // two files joined), so what was read may not be what was meant.
    if (h.format != PlyFormat::Ascii && in.peek() != std::ifstream::traits_type::eof())
        fail_in_file(path, "data after the last declared record (a wrong element count?)");
    for (std::size_t k = 0; k < table.names.size(); ++k)
        for (std::size_t i = 0; i < table.count; ++i)
            if (!std::isfinite(table.columns[k][i]))
                fail_in_file(
                    path, "vertex " + std::to_string(i) + " property '" + table.names[k] + "' is not finite");
    return table;
}

void write_ply_vertices(const std::string& path, const PlyVertexTable& table) {
    write_atomically(path, [&](const std::string& tmp) {
        std::ofstream out(tmp, std::ios::binary);
        if (!out) fail_in_file(tmp, "cannot open for writing");
        out << "ply\nformat binary_little_endian 1.0\ncomment written by lumigauss\n";
        out << "element vertex " << table.count << "\n";
        for (const auto& n : table.names) out << "property float " << n << "\n";
        out << "end_header\n";
        std::vector<float> row(table.names.size());
        for (std::size_t i = 0; i < table.count; ++i) {
            for (std::size_t k = 0; k < row.size(); ++k) {
                float v = table.columns[k][i];
                if constexpr (std::endian::native == std::endian::big) {
                    auto* b = reinterpret_cast<unsigned char*>(&v);
                    std::reverse(b, b + 4);
                }
                row[k] = v;
            }
            out.write(reinterpret_cast<const char*>(row.data()), std::streamsize(row.size() * sizeof(float)));
        }
        out.flush();
        if (!out) fail_in_file(tmp, "write failed (disk full?)");
    });
}

}  // namespace lumigauss
