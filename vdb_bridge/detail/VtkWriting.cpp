// See VtkWriting.h.
#include "vdb_bridge/detail/VtkWriting.h"

#include <algorithm>
#include <filesystem>

#include <unistd.h>

#include <vtkCompositeDataSet.h>
#include <vtkErrorCode.h>
#include <vtkImageData.h>
#include <vtkInformation.h>
#include <vtkNew.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLImageDataWriter.h>
#include <vtkXMLMultiBlockDataWriter.h>
#include <vtkXMLUnstructuredGridWriter.h>
#include <vtkXMLWriter.h>

#include "src/util/AtomicFile.h"
#include "src/util/Error.h"
#include "src/util/TemporaryFiles.h"

namespace vdbdag::bridge::detail {
namespace fs = std::filesystem;

Compressor parseCompressor(const std::string& name) {
    if (name == "zlib") return Compressor::ZLib;
    if (name == "lz4") return Compressor::LZ4;
    throw Error("unknown compressor '" + name + "' (use zlib or lz4)");
}

std::string extensionOf(const std::string& path) {
    std::string ext = fs::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    return ext;
}

void setBlock(vtkMultiBlockDataSet* blocks, unsigned index, vtkDataObject* block, const std::string& name) {
    blocks->SetBlock(index, block);
    blocks->GetMetaData(index)->Set(vtkCompositeDataSet::NAME(), name.c_str());
}

uint64_t writtenBytes(const std::string& path) {
    std::error_code ec;
    uint64_t bytes = fs::file_size(path, ec);
    if (ec) bytes = 0;
    if (extensionOf(path) == ".vtm") {
        const fs::path dest(path);
        const fs::path pieces = (dest.parent_path().empty() ? fs::path(".") : dest.parent_path()) / dest.stem();
        for (const auto& entry : fs::recursive_directory_iterator(pieces, ec))
            if (entry.is_regular_file(ec)) bytes += entry.file_size(ec);
    }
    return bytes;
}

namespace {

void configure(vtkXMLWriter* writer, Compressor compressor) {
    writer->SetDataModeToAppended();
    writer->EncodeAppendedDataOff();  // raw binary, not base64
    writer->SetHeaderTypeToUInt64();
    if (compressor == Compressor::LZ4) writer->SetCompressorTypeToLZ4();
    else writer->SetCompressorTypeToZLib();
}

void run(vtkXMLWriter* writer, const std::string& path) {
    const int ok = writer->Write();
    const unsigned long code = writer->GetErrorCode();
    if (!ok || code != vtkErrorCode::NoError)
        throw Error(path + ": VTK could not write the file (" +
                    (code != vtkErrorCode::NoError ? std::string(vtkErrorCode::GetStringFromErrorCode(code)) : std::string("writer failed")) + ")");
}

// Quiets VTK's own error window for the duration of a write; errors are reported as vdbdag::Error.
struct QuietVtk {
    int previous = vtkObject::GetGlobalWarningDisplay();
    QuietVtk() { vtkObject::GlobalWarningDisplayOff(); }
    ~QuietVtk() { vtkObject::SetGlobalWarningDisplay(previous); }
};

void writeMultiBlock(vtkMultiBlockDataSet* blocks, const std::string& path, Compressor compressor) {
    const fs::path dest(path);
    const fs::path folder = dest.parent_path().empty() ? fs::path(".") : dest.parent_path();
    const std::string stem = dest.stem().string();
    const fs::path pieces = folder / stem;  // where the .vtm's pieces live
    std::error_code ec;
    if (fs::exists(pieces, ec)) {
        if (!fs::is_directory(pieces, ec)) throw Error(path + ": " + pieces.string() + " exists and is not a folder (the .vtm's pieces go there)");
        for (const auto& entry : fs::directory_iterator(pieces, ec))
            if (entry.path().filename().string().rfind(stem + "_", 0) != 0)
                throw Error(path + ": folder " + pieces.string() + " holds other files than an earlier export's pieces; not overwriting it");
    }
    removeStaleTemporaries(path);
    const fs::path temporary = temporaryNameFor(path);
    TemporaryGuard guard(temporary.string(), /*folder=*/true);
    if (!fs::create_directory(temporary, ec)) throw Error(path + ": cannot create a temporary folder in " + folder.string() + " (" + ec.message() + ")");
    try {
        vtkNew<vtkXMLMultiBlockDataWriter> writer;
        configure(writer, compressor);
        writer->SetInputData(blocks);
        writer->SetFileName((temporary / dest.filename()).string().c_str());
        run(writer, path);
        // Replace the earlier pieces (if any), then the .vtm itself last.
        if (fs::exists(pieces, ec)) fs::remove_all(pieces);
        if (fs::exists(temporary / stem)) fs::rename(temporary / stem, pieces);
        moveIntoPlace((temporary / dest.filename()).string(), dest.string());  // a new .vtm never replaces one made meanwhile
        fs::remove_all(temporary);
    } catch (const fs::filesystem_error& e) {
        fs::remove_all(temporary, ec);
        throw Error(path + ": cannot move the written files into place (" + e.code().message() + ")");
    } catch (...) {
        fs::remove_all(temporary, ec);
        throw;
    }
}

} // namespace

void writeVtk(vtkDataObject* data, const std::string& path, Compressor compressor) {
    QuietVtk quiet;
    const std::string ext = extensionOf(path);
    if (ext == ".vtm") {
        auto* blocks = vtkMultiBlockDataSet::SafeDownCast(data);
        if (!blocks) throw Error(path + ": internal error: a .vtm needs a multiblock data set");
        writeMultiBlock(blocks, path, compressor);
        return;
    }
    writeViaTemporary(path, [&](const std::string& temporary) {
        if (ext == ".vtu") {
            vtkNew<vtkXMLUnstructuredGridWriter> writer;
            configure(writer, compressor);
            writer->SetInputData(vtkUnstructuredGrid::SafeDownCast(data));
            writer->SetFileName(temporary.c_str());
            run(writer, path);
        } else if (ext == ".vti") {
            vtkNew<vtkXMLImageDataWriter> writer;
            configure(writer, compressor);
            writer->SetInputData(vtkImageData::SafeDownCast(data));
            writer->SetFileName(temporary.c_str());
            run(writer, path);
        } else {
            throw Error(path + ": unknown output type '" + ext + "' (use .vtu, .vti or .vtm)");
        }
    });
}

} // namespace vdbdag::bridge::detail
