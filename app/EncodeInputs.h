// `vdbdag encode INPUT... [-o OUT]` as one library call, for the command line
// and other programs (Python's vdbdag.encode): which inputs make one file,
// a sequence file, or one file each, and the encodes that follow.
//   - one input (a file, a DICOM folder or several DICOM inputs read as one
//     set): one .ssvdag, -o or IN.ssvdag beside it (EncodeFile.h);
//   - a frame pattern (smoke.####.vdb, %04d, $F4), a folder of .vdb/.nvdb
//     frames, or several other inputs with -o NAME.ssvdag: one sequence file
//     holding every frame (EncodeSequence.h), each frame coded alone;
//   - several other inputs otherwise: one .ssvdag each, in the folder -o
//     names or beside each input (EncodeOutputs.h).
#pragma once
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "app/DenseInputs.h"
#include "app/EncodeFile.h"
#include "src/util/FramePattern.h"

namespace vdbdag::app {

struct EncodeInputsRequest {
    std::vector<std::string> inputs;
    std::string output;     // a file, a folder for several files, or empty (the default name)
    EncodeRequest coding;   // how every file is coded and where; its input, output, inputFiles and dense are set per input here
    DenseInputs dense;      // a dense input's options (coding.dense is resolved from them per input)
};

struct EncodeInputsHooks {
    EncodeHooks file;  // the team (mpirun) and the warnings and notes of a lone file's encode
    // Called before each input is read (the command names it if memory runs out).
    std::function<void(const std::string& input)> onInput;
    // Each file of several written one file each, as it is written.
    std::function<void(const nlohmann::json& report)> onFile;
};

enum class EncodeShape { OneFile, Sequence, FileEach };

struct EncodeInputsResult {
    EncodeShape shape = EncodeShape::OneFile;
    bool written = false;          // false on a process of an mpirun team other than the first
    std::string output;            // the file written (one file or a sequence) or the folder (several)
    nlohmann::json report;         // as `encode --json` prints it: an object, or an array for several files
    bridge::ThresholdReport threshold;  // one file: a dense scan's threshold, for the text report
    std::vector<FrameFile> frames;      // a sequence: its frames
};

// Throws vdbdag::Error naming the input or output on a refusal; no output
// appears then (each file appears whole or not at all).
EncodeInputsResult encodeInputs(const EncodeInputsRequest& request, const EncodeInputsHooks& hooks = {});

} // namespace vdbdag::app
