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

// A property's scalar type, resolved once from its name in the header (the reader used to compare the type
// names for every value: two thirds of loading a model).
enum class PlyScalar : std::uint8_t { Int8, UInt8, Int16, UInt16, Int32, UInt32, Float32, Float64 };

PlyScalar parse_scalar(const std::string& type, const std::string& file) {
    if (type == "char" || type == "int8") return PlyScalar::Int8;
    if (type == "uchar" || type == "uint8") return PlyScalar::UInt8;
    if (type == "short" || type == "int16") return PlyScalar::Int16;
    if (type == "ushort" || type == "uint16") return PlyScalar::UInt16;
    if (type == "int" || type == "int32") return PlyScalar::Int32;
    if (type == "uint" || type == "uint32") return PlyScalar::UInt32;
    if (type == "float" || type == "float32") return PlyScalar::Float32;
    if (type == "double" || type == "float64") return PlyScalar::Float64;
    fail_in_file(file, "unknown PLY property type '" + type + "'");
}

int scalar_size(PlyScalar type) {
    switch (type) {
        case PlyScalar::Int8:
        case PlyScalar::UInt8:
            return 1;
        case PlyScalar::Int16:
        case PlyScalar::UInt16:
            return 2;
        case PlyScalar::Int32:
        case PlyScalar::UInt32:
        case PlyScalar::Float32:
            return 4;
        case PlyScalar::Float64:
            return 8;
    }
    return 8;
}

struct PlyProperty {
    std::string name;
    PlyScalar type = PlyScalar::Float32;  // scalar type, or the item type of a list
    bool is_list = false;
    PlyScalar list_size = PlyScalar::UInt8;  // the type of a list's item count
};

struct PlyElement {
    std::string name;
    std::size_t count = 0;
    std::vector<PlyProperty> properties;
};

template <typename T>
T load_swapped(const unsigned char* p, bool swap) {
    unsigned char b[sizeof(T)];
    std::memcpy(b, p, sizeof(T));
    if (swap) std::reverse(b, b + sizeof(T));
    T v;
    std::memcpy(&v, b, sizeof(T));
    return v;
}

double decode(PlyScalar type, const unsigned char* p, bool swap) {
    switch (type) {
        case PlyScalar::Int8:
            return load_swapped<std::int8_t>(p, swap);
        case PlyScalar::UInt8:
            return load_swapped<std::uint8_t>(p, swap);
        case PlyScalar::Int16:
            return load_swapped<std::int16_t>(p, swap);
        case PlyScalar::UInt16:
            return load_swapped<std::uint16_t>(p, swap);
        case PlyScalar::Int32:
            return load_swapped<std::int32_t>(p, swap);
        case PlyScalar::UInt32:
            return load_swapped<std::uint32_t>(p, swap);
        case PlyScalar::Float32:
            return load_swapped<float>(p, swap);
        case PlyScalar::Float64:
            return load_swapped<double>(p, swap);
    }
    return 0;
}

// The bytes of one record of an element without list properties.
std::size_t record_size(const PlyElement& e) {
    std::size_t record = 0;
    for (const auto& p : e.properties) record += std::size_t(scalar_size(p.type));
    return record;
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
            std::string t, count_type;
            ls >> t;
            p.is_list = t == "list";
            if (p.is_list)
                ls >> count_type >> t >> p.name;
            else
                ls >> p.name;
            if (!ls) fail_in_file(path, where + "malformed property line '" + line + "'");
            p.type = parse_scalar(t, path);
            if (p.is_list) p.list_size = parse_scalar(count_type, path);
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
    const bool has_list =
        std::any_of(e.properties.begin(), e.properties.end(), [](const PlyProperty& p) { return p.is_list; });
    if (has_list && table) fail_in_file(path, "list properties in the vertex element are not supported");
    const auto truncated_at = [&](std::size_t record) {
        fail_in_file(path, "truncated: element '" + e.name + "' promises " + std::to_string(e.count) +
                               " records, the file ends in record " + std::to_string(record));
    };
    if (has_list) {
        unsigned char count_bytes[8];
        for (std::size_t i = 0; i < e.count; ++i)
            for (const auto& p : e.properties) {
                const int size = scalar_size(p.is_list ? p.list_size : p.type);
                if (!in.read(reinterpret_cast<char*>(count_bytes), size)) truncated_at(i);
                if (!p.is_list) continue;
                const auto n = std::size_t(decode(p.list_size, count_bytes, swap));
                in.ignore(std::streamsize(n * std::size_t(scalar_size(p.type))));
                if (!in) truncated_at(i);
            }
        return;
    }
    // Fixed-size records, read a block of them at a time.
    const std::size_t record = record_size(e);
    const std::size_t block_records = std::max<std::size_t>(1, (std::size_t(1) << 16) / record);
    std::vector<unsigned char> block(std::min(block_records, e.count) * record);
    for (std::size_t first = 0; first < e.count; first += block_records) {
        const std::size_t n = std::min(block_records, e.count - first);
        in.read(reinterpret_cast<char*>(block.data()), std::streamsize(n * record));
        if (!in) truncated_at(first + std::size_t(in.gcount()) / record);
        if (!table) continue;
        std::size_t offset = 0;  // of property k in a record
        for (std::size_t k = 0; k < e.properties.size(); ++k) {
            float* column = table->columns[k].data() + first;
            const PlyScalar type = e.properties[k].type;
            const unsigned char* value = block.data() + offset;
            for (std::size_t i = 0; i < n; ++i, value += record) column[i] = float(decode(type, value, swap));
            offset += std::size_t(scalar_size(type));
        }
    }
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
    const std::uint64_t record = format == PlyFormat::Ascii ? 2 * e.properties.size() : record_size(e);
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
        if (e.name == "vertex") {
            // Two vertex elements: which one is the model? And one without properties holds no bytes, so the
            // file cannot bound its count, which the readers above size their models by (a 184-byte file
            // declaring 671,698,203,059 vertices made load_relightable_ply ask for 8 TB; libFuzzer,
            // fuzz/regressions/relightable_ply/vertex_without_properties).
            if (found) fail_in_file(path, "the 'vertex' element is declared twice");
            if (e.properties.empty())
                fail_in_file(path, "the 'vertex' element declares " + std::to_string(e.count) +
                                       " vertices but no properties");
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
