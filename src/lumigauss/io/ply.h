#pragma once
// PLY files with scalar vertex properties: the container of 3DGS/2DGS models and of our exports.
// Reads ascii, binary_little_endian and binary_big_endian; elements other than "vertex" (faces, say) are
// skipped, list properties included. Writes binary_little_endian float properties.
#include <cstddef>
#include <string>
#include <vector>

namespace lumigauss {

struct PlyVertexTable {
    std::size_t count = 0;
    std::vector<std::string> names;           // property names in file order
    std::vector<std::vector<float>> columns;  // one column per property

    bool has(const std::string& name) const;
    // The column of `name`; throws lumigauss::Error naming `file` if it is missing.
    const std::vector<float>& column(const std::string& name, const std::string& file) const;
    void add(const std::string& name, std::vector<float> values);
};

PlyVertexTable read_ply_vertices(const std::string& path);
// Written atomically (temp file + rename).
void write_ply_vertices(const std::string& path, const PlyVertexTable& table);

}  // namespace lumigauss
