// Private: writing VTK XML files the way ParaView reads them fastest: binary,
// compressed (zlib or lz4), appended raw data, 64-bit headers. Every write is
// atomic: a .vtu/.vti goes through a temporary file; a .vtm (whose pieces
// vtkXMLMultiBlockDataWriter puts in a folder named after it) is written
// into a temporary folder and moved into place, so a failure leaves nothing.
#pragma once
#include <cstdint>
#include <string>

#include <vtkDataObject.h>
#include <vtkMultiBlockDataSet.h>

namespace vdbdag::bridge::detail {

enum class Compressor { ZLib, LZ4 };
Compressor parseCompressor(const std::string& name);  // "zlib" | "lz4"; throws vdbdag::Error

// `path` must end in .vtu (vtkUnstructuredGrid), .vti (vtkImageData) or .vtm
// (vtkMultiBlockDataSet). Throws vdbdag::Error("PATH: ...").
void writeVtk(vtkDataObject* data, const std::string& path, Compressor compressor);

// Lower-case extension of `path` (".vtu", ...).
std::string extensionOf(const std::string& path);

// Bytes written for `path` (a .vtm: itself plus its pieces folder).
uint64_t writtenBytes(const std::string& path);

// Sets a block's name (shown by ParaView's multiblock inspector).
void setBlock(vtkMultiBlockDataSet* blocks, unsigned index, vtkDataObject* block, const std::string& name);

} // namespace vdbdag::bridge::detail
