// Any input vdbdag reads as a scene: an .ssvdag file as it is read, a .vdb,
// a NanoVDB .nvdb or a dense scan (raw, NRRD, MetaImage, NIfTI, DICOM)
// imported and encoded in memory with `encode`'s defaults, so that a command
// that needs a DAG (render) takes every input and shows the same picture
// as for the .ssvdag `encode` would write.
#pragma once
#include <string>

#include "src/format/SsvdagFile.h"

namespace vdbdag::bridge {

enum class InputKind { Ssvdag, Vdb, NanoVdb, Dense };

// By the magic number of a regular file (.ssvdag, OpenVDB, NanoVDB), else
// by name (a scan's extension or a DICOM folder); Ssvdag for anything else,
// whose reader then says what it is.
InputKind inputKindOf(const std::string& path);

// Throws vdbdag::Error naming the file; `readOptions` apply to an .ssvdag.
format::SsvdagScene sceneOfInput(const std::string& path, const format::ReadOptions& readOptions);

} // namespace vdbdag::bridge
