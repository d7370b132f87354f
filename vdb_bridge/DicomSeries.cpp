// See DicomSeries.h. GDCM reads the headers (detail/DicomFileHeader.h:
// gdcm::Reader up to the Pixel Data, then a second look for the Pixel Data
// element itself) once the element walk (detail/DicomElementWalk.h) has
// passed the file; native pixel
// data are read where the walk found them, compressed ones are decoded by
// gdcm::ImageReader (any transfer syntax it supports).
// Every file, or every frame of a multi-frame file, becomes one candidate
// slice; candidates are grouped by Series Instance UID, rows/columns and
// Image Orientation (Patient), and each group is sorted by its position along
// the slice normal. What makes a group unconvertible (duplicates, gaps,
// mixed rescales, colour samples) is found at scan time and kept as its
// `problem`, so `info` can show it and describeDicomSeries refuses with it.
#include "vdb_bridge/DicomSeries.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cctype>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <optional>
#include <set>

#include <fmt/core.h>

#include <gdcmDataSet.h>
#include <gdcmImage.h>
#include <gdcmImageReader.h>
#include <gdcmMediaStorage.h>
#include <gdcmReader.h>
#include <gdcmSequenceOfItems.h>
#include <gdcmStringFilter.h>
#include <gdcmTrace.h>
#include <gdcmUIDs.h>

#include "src/util/Error.h"
#include "vdb_bridge/DicomTags.h"
#include "vdb_bridge/detail/DicomElementWalk.h"
#include "vdb_bridge/detail/DicomFileHeader.h"
#include "vdb_bridge/detail/DicomRle.h"

namespace vdbdag::bridge {
namespace {

namespace fs = std::filesystem;
using detail::cross;
using detail::dicomdirFiles;
using detail::dot;
using detail::elementLengthProblem;
using detail::Fields;
using detail::FileInfo;
using detail::Frame;
using detail::kPixelGroup;
using detail::norm;
using detail::quietGdcm;
using detail::readFile;
using detail::scaled;
using detail::sub;
using detail::trim;
using detail::Vec3;



std::string formatNumber(double v) { return fmt::format("{:.6g}", v); }
std::string formatVec(const Vec3& v) { return fmt::format("({:.6g}, {:.6g}, {:.6g})", v[0], v[1], v[2]); }



struct Group {
    DicomSeriesInfo info;
    FileInfo first;  // the first file's shared values (bits, samples)
    std::vector<Frame> frames;
    std::vector<const FileInfo*> files;  // parallel to frames
    std::string problem;                 // empty when convertible
    // The slice index of each frame: consecutive, except where slices are
    // missing (a step of k times the series' step leaves k - 1 empty slots).
    std::vector<int64_t> slots;
    std::vector<int64_t> missing;  // the empty slots
    Vec3 rowDir{1, 0, 0}, colDir{0, 1, 0}, normal{0, 0, 1};
    std::optional<SampleType> type;
};

struct ScanState {
    DicomScan scan;
    std::vector<std::unique_ptr<FileInfo>> files;
    std::vector<Group> groups;  // parallel to scan.series
};



bool isDicomdirName(const fs::path& p) {
    std::string name = p.filename().string();
    std::transform(name.begin(), name.end(), name.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    return name == "dicomdir";
}

std::optional<SampleType> sampleTypeOf(unsigned bits, unsigned representation) {
    if (bits == 8) return representation ? SampleType::I8 : SampleType::U8;
    if (bits == 16) return representation ? SampleType::I16 : SampleType::U16;
    if (bits == 32) return representation ? SampleType::I32 : SampleType::U32;
    return std::nullopt;
}

bool sameOrientation(const std::array<double, 6>& a, const std::array<double, 6>& b) {
    for (size_t i = 0; i < 6; ++i)
        if (std::abs(a[i] - b[i]) > 1e-4) return false;
    return true;
}

std::string frameName(const Frame& fr, const FileInfo&) { return fr.multiFrame ? fmt::format("{} (frame {})", fr.file, fr.frame + 1) : fr.file; }

// Sorts the group's frames along the normal and finds what keeps it from
// being one regular grid.
void analyse(Group& g) {
    const auto& o = g.frames.front().orientation;
    g.rowDir = {o[0], o[1], o[2]};
    g.colDir = {o[3], o[4], o[5]};
    Vec3 n = cross(g.rowDir, g.colDir);
    const double nn = norm(n);
    const auto fail = [&](const std::string& why) {
        if (g.problem.empty()) g.problem = why;
    };
    if (!(nn > 1e-6) || std::abs(norm(g.rowDir) - 1) > 1e-3 || std::abs(norm(g.colDir) - 1) > 1e-3)
        fail("Image Orientation (Patient) " + fmt::format("{:.6g}\\{:.6g}\\{:.6g}\\{:.6g}\\{:.6g}\\{:.6g}", o[0], o[1], o[2], o[3], o[4], o[5]) +
             " is not two unit directions");
    g.normal = nn > 0 ? scaled(n, 1 / nn) : Vec3{0, 0, 1};

    // Order by position along the normal (ties: by file, frame).
    std::vector<size_t> order(g.frames.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::vector<double> s(g.frames.size());
    for (size_t i = 0; i < s.size(); ++i) s[i] = dot(g.frames[i].position, g.normal);
    std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
        if (s[a] != s[b]) return s[a] < s[b];
        if (g.frames[a].file != g.frames[b].file) return g.frames[a].file < g.frames[b].file;
        return g.frames[a].frame < g.frames[b].frame;
    });
    std::vector<Frame> frames;
    std::vector<const FileInfo*> files;
    std::vector<double> sorted;
    for (size_t i : order) {
        frames.push_back(g.frames[i]);
        files.push_back(g.files[i]);
        sorted.push_back(s[i]);
    }
    g.frames = std::move(frames);
    g.files = std::move(files);
    const size_t count = g.frames.size();

    // Samples.
    g.first = *g.files.front();
    if (g.first.samplesPerPixel != 1)
        fail(fmt::format("{} samples per pixel (Photometric Interpretation {}); only greyscale (1 sample per pixel) is supported for now",
                         g.first.samplesPerPixel, g.first.photometric.empty() ? "unknown" : g.first.photometric));
    else if (g.first.photometric == "PALETTE COLOR")
        fail("PALETTE COLOR (indexed colour); only greyscale is supported for now");
    else if (!g.first.photometric.empty() && g.first.photometric != "MONOCHROME1" && g.first.photometric != "MONOCHROME2")
        fail(fmt::format("Photometric Interpretation '{}' is no greyscale DICOM defines (MONOCHROME1 or MONOCHROME2)", g.first.photometric));
    for (const FileInfo* f : g.files)
        if (!f->damaged.empty()) {
            fail(f->file + " " + f->damaged);
            break;
        }
    g.type = sampleTypeOf(g.first.bitsAllocated, g.first.pixelRepresentation);
    if (!g.type) fail(fmt::format("Bits Allocated {}; only 8, 16 or 32 are supported", g.first.bitsAllocated));
    for (size_t i = 1; i < count; ++i) {
        const FileInfo& b = *g.files[i];
        if (b.bitsAllocated != g.first.bitsAllocated || b.pixelRepresentation != g.first.pixelRepresentation ||
            b.samplesPerPixel != g.first.samplesPerPixel) {
            fail(fmt::format("{} (Bits Allocated {}, Pixel Representation {}) and {} (Bits Allocated {}, Pixel Representation {}) store "
                             "different sample types",
                             g.first.file, g.first.bitsAllocated, g.first.pixelRepresentation, b.file, b.bitsAllocated, b.pixelRepresentation));
            break;
        }
    }

    // Rescale and pixel spacing: one value for the whole series.
    const Frame& f0 = g.frames.front();
    for (size_t i = 1; i < count; ++i) {
        const Frame& f = g.frames[i];
        if (f.slope != f0.slope || f.intercept != f0.intercept) {
            fail(fmt::format("Rescale Slope/Intercept differ between slices ({}: {}/{}, {}: {}/{}); one rescale per series is supported",
                             frameName(f0, *g.files.front()), formatNumber(f0.slope), formatNumber(f0.intercept), frameName(f, *g.files[i]),
                             formatNumber(f.slope), formatNumber(f.intercept)));
            break;
        }
    }
    for (size_t i = 1; i < count; ++i) {
        const Frame& f = g.frames[i];
        if (std::abs(f.rowSpacing - f0.rowSpacing) > 1e-4 * f0.rowSpacing || std::abs(f.columnSpacing - f0.columnSpacing) > 1e-4 * f0.columnSpacing) {
            fail(fmt::format("Pixel Spacing differs between slices ({}: {}\\{}, {}: {}\\{})", frameName(f0, *g.files.front()),
                             formatNumber(f0.rowSpacing), formatNumber(f0.columnSpacing), frameName(f, *g.files[i]), formatNumber(f.rowSpacing),
                             formatNumber(f.columnSpacing)));
            break;
        }
    }
    if (!f0.pixelSpacingGiven) g.info.notes.push_back("no Pixel Spacing: 1 mm assumed in-plane");

    // Positions: no duplicates, one regular step, on one line.
    double step = f0.thickness > 0 ? f0.thickness : 1;
    if (count > 1) {
        const double span = sorted.back() - sorted.front();
        for (size_t i = 0; i + 1 < count; ++i) {
            if (std::abs(sorted[i + 1] - sorted[i]) <= 1e-6 * std::max(1.0, std::abs(span))) {
                fail(fmt::format("{} and {} are at the same slice position ({} mm along the normal): duplicate slices", frameName(g.frames[i], *g.files[i]),
                                 frameName(g.frames[i + 1], *g.files[i + 1]), formatNumber(sorted[i])));
                g.info.notes.push_back("duplicate slice positions");
                break;
            }
        }
        std::vector<double> steps;
        for (size_t i = 0; i + 1 < count; ++i) steps.push_back(sorted[i + 1] - sorted[i]);
        std::vector<double> tmp = steps;
        std::nth_element(tmp.begin(), tmp.begin() + ptrdiff_t(tmp.size() / 2), tmp.end());
        const double median = tmp[tmp.size() / 2];
        step = median;
        g.slots.assign(1, 0);
        if (g.problem.empty() && median > 0) {
            std::vector<std::string> bad, gaps;
            size_t badCount = 0;
            for (size_t i = 0; i < steps.size(); ++i) {
                // A step of k (>= 2) series steps: k - 1 missing slices,
                // kept as empty slots so the spacing stays regular.
                const double k = std::round(steps[i] / median);
                if (k >= 2 && std::abs(steps[i] - k * median) <= 2e-3 * k * median) {
                    for (int64_t m = 1; m < int64_t(k); ++m) g.missing.push_back(g.slots.back() + m);
                    if (gaps.size() < 4)
                        gaps.push_back(fmt::format("{} after {} mm ({})", int64_t(k) - 1, formatNumber(sorted[i]), frameName(g.frames[i], *g.files[i])));
                    g.slots.push_back(g.slots.back() + int64_t(k));
                    continue;
                }
                g.slots.push_back(g.slots.back() + 1);
                if (std::abs(steps[i] - median) <= 1e-3 * median) continue;
                if (++badCount <= 4)
                    bad.push_back(fmt::format("{} mm ({}) -> {} mm ({}), a step of {} mm", formatNumber(sorted[i]), frameName(g.frames[i], *g.files[i]),
                                              formatNumber(sorted[i + 1]), frameName(g.frames[i + 1], *g.files[i + 1]), formatNumber(steps[i])));
            }
            if (badCount) {
                std::string list;
                for (size_t i = 0; i < bad.size(); ++i) list += (i ? ", " : "") + bad[i];
                if (badCount > bad.size()) list += fmt::format(" and {} more", badCount - bad.size());
                fail(fmt::format("uneven slice spacing or missing slices: the median step is {} mm, but along the normal {}",
                                 formatNumber(median), list));
                g.info.notes.push_back("uneven spacing or missing slices");
            }
            if (!g.missing.empty()) {
                std::string list;
                for (size_t i = 0; i < gaps.size(); ++i) list += (i ? ", " : "") + gaps[i];
                g.info.notes.push_back(fmt::format("{} missing slice{} ({}{}): kept as empty slices, inactive voxels with no data, at the regular {} mm step",
                                                   g.missing.size(), g.missing.size() == 1 ? "" : "s", list, gaps.size() < g.missing.size() ? ", ..." : "",
                                                   formatNumber(median)));
            }
        }
        if (g.problem.empty()) {
            const double last = double(g.slots.back());
            const Vec3 axis = scaled(sub(g.frames.back().position, f0.position), 1.0 / last);
            double worst = 0;
            size_t at = 0;
            for (size_t i = 0; i < count; ++i) {
                const double t = double(g.slots[i]);
                const Vec3 expect{f0.position[0] + t * axis[0], f0.position[1] + t * axis[1], f0.position[2] + t * axis[2]};
                const double d = norm(sub(g.frames[i].position, expect));
                if (d > worst) { worst = d; at = i; }
            }
            if (worst > 1e-2 * norm(axis))
                fail(fmt::format("the slice positions do not lie on a line: {} is at {}, {} mm off", frameName(g.frames[at], *g.files[at]),
                                 formatVec(g.frames[at].position), formatNumber(worst)));
            const double cosAngle = dot(axis, g.normal) / norm(axis);
            if (cosAngle < 1 - 1e-6)
                g.info.notes.push_back(fmt::format("sheared stack (slices step {:.3g} degrees off the normal, e.g. gantry tilt)",
                                                   std::acos(std::min(1.0, cosAngle)) * 180 / M_PI));
        }
    }

    if (g.slots.size() != count) {  // one slice, or a refused series
        g.slots.resize(count);
        for (size_t i = 0; i < count; ++i) g.slots[i] = int64_t(i);
        g.missing.clear();
    }
    g.info.dims = {int64_t(g.first.columns), int64_t(g.first.rows), g.slots.empty() ? 0 : g.slots.back() + 1};
    g.info.missingSlices = int64_t(g.missing.size());
    g.info.spacing = {f0.columnSpacing, f0.rowSpacing, step};
    g.info.sampleType = g.type ? sampleTypeName(*g.type) : "";
    g.info.problem = g.problem;
    std::set<std::string> distinctFiles;
    for (const Frame& f : g.frames) distinctFiles.insert(f.file);
    if (distinctFiles.size() < count) g.info.notes.push_back(fmt::format("multi-frame: {} frames from {} file(s)", count, distinctFiles.size()));
}

// The files one input names: a folder's files (recursively, sorted), the
// files a DICOMDIR lists, or the file itself. `fromFolder` says which.
std::vector<std::string> inputFiles(const std::string& path, ScanState& st, bool& fromFolder) {
    std::error_code ec;
    const fs::path root(path);
    if (!fs::exists(root, ec)) throw Error(path + ": does not exist");
    std::vector<std::string> candidates;
    fromFolder = false;
    if (fs::is_directory(root, ec)) {
        fromFolder = true;
        fs::recursive_directory_iterator it(root, fs::directory_options::skip_permission_denied, ec), end;
        if (ec) throw Error(path + ": cannot list the folder (" + ec.message() + ")");
        for (; it != end; it.increment(ec)) {
            if (ec) throw Error(path + ": cannot list the folder (" + ec.message() + ")");
            std::error_code fe;
            if (it->is_regular_file(fe)) candidates.push_back(it->path().string());
        }
        std::sort(candidates.begin(), candidates.end());
        if (candidates.empty()) throw Error(path + ": the folder holds no files");
    } else if (fs::is_regular_file(root, ec)) {
        bool dicomdir = isDicomdirName(root);
        if (!dicomdir) {  // a DICOMDIR by its Media Storage SOP Class, whatever its name
            quietGdcm();
            gdcm::Reader r;
            r.SetFileName(path.c_str());
            if (elementLengthProblem(path).empty() && r.ReadUpToTag(gdcm::Tag(0x0004, 0x1220))) {
                const Fields f(r.GetFile());
                dicomdir = f.text(r.GetFile().GetHeader(), 0x0002, 0x0002) == "1.2.840.10008.1.3.10";
            }
        }
        candidates = dicomdir ? dicomdirFiles(path, st.scan.skipped) : std::vector<std::string>{path};
        if (dicomdir && candidates.empty())
            throw Error(path + ": the DICOMDIR lists no files that exist" + (st.scan.skipped.empty() ? std::string() : " (e.g. " + st.scan.skipped.front() + ")"));
    } else {
        throw Error(path + ": is neither a folder nor a regular file");
    }
    return candidates;
}

ScanState scan(const std::vector<std::string>& paths) {
    ScanState st;
    if (paths.empty()) throw Error("no DICOM input given");
    std::vector<std::pair<std::string, bool>> candidates;  // file, found in a folder
    std::set<std::string> seenFiles;
    for (const std::string& path : paths) {
        bool fromFolder = false;
        for (std::string& file : inputFiles(path, st, fromFolder)) {
            std::error_code ec;
            const fs::path canonical = fs::weakly_canonical(file, ec);
            if (!seenFiles.insert(ec ? file : canonical.string()).second) continue;  // a file named twice (or in two inputs) is read once
            candidates.emplace_back(std::move(file), fromFolder);
        }
    }

    for (const auto& [file, fromFolder] : candidates) {
        if (fromFolder && isDicomdirName(file)) {
            st.scan.skipped.push_back(file + ": a DICOMDIR (the files in the folder are scanned themselves)");
            continue;
        }
        auto info = std::make_unique<FileInfo>();
        std::vector<Frame> frames;
        std::string why;
        try {
            why = readFile(file, *info, frames);
        } catch (const Error& e) {  // a header GDCM's text reading would abort on (detail::Fields::text)
            why = std::string("corrupt DICOM: ") + e.what();
        }
        if (!why.empty()) {
            st.scan.skipped.push_back(file + ": " + why);
            continue;
        }
        for (const Frame& fr : frames) {
            Group* target = nullptr;
            for (Group& g : st.groups)
                if (g.info.uid == info->seriesUid && g.first.rows == info->rows && g.first.columns == info->columns &&
                    sameOrientation(g.frames.front().orientation, fr.orientation)) {
                    target = &g;
                    break;
                }
            if (!target) {
                Group g;
                g.info.uid = info->seriesUid;
                g.info.modality = info->modality;
                g.info.description = info->description;
                g.info.seriesNumber = info->seriesNumber;
                g.first = *info;
                st.groups.push_back(std::move(g));
                target = &st.groups.back();
            }
            target->frames.push_back(fr);
            target->files.push_back(info.get());
        }
        st.files.push_back(std::move(info));
    }

    // Listing order: series number, UID, then the order parts were found.
    std::vector<size_t> order(st.groups.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
        const DicomSeriesInfo &x = st.groups[a].info, &y = st.groups[b].info;
        if (x.seriesNumber != y.seriesNumber) return x.seriesNumber < y.seriesNumber;
        return x.uid < y.uid;
    });
    std::vector<Group> groups;
    for (size_t i : order) groups.push_back(std::move(st.groups[i]));
    st.groups = std::move(groups);
    std::map<std::string, int> parts;
    for (const Group& g : st.groups) ++parts[g.info.uid];
    std::map<std::string, int> seen;
    for (Group& g : st.groups) {
        analyse(g);
        if (parts[g.info.uid] > 1)
            g.info.notes.insert(g.info.notes.begin(), fmt::format("part {} of {} of this Series Instance UID (split by orientation or image size)",
                                                                   ++seen[g.info.uid], parts[g.info.uid]));
        st.scan.series.push_back(g.info);
    }
    return st;
}

std::string oneLine(size_t index, const DicomSeriesInfo& s) {
    std::string line = fmt::format("{}) {} {} \"{}\" {}x{}x{}", index + 1, s.uid, s.modality.empty() ? "?" : s.modality, s.description, s.dims[0],
                                   s.dims[1], s.dims[2]);
    if (!s.problem.empty()) line += " (not convertible)";
    return line;
}

std::string listing(const DicomScan& scan) {
    std::string out;
    for (size_t i = 0; i < scan.series.size(); ++i) out += (i ? "; " : "") + oneLine(i, scan.series[i]);
    return out;
}

} // namespace

DicomScan scanDicom(const std::vector<std::string>& inputs) { return scan(inputs).scan; }

std::string dicomInputName(const std::vector<std::string>& inputs) {
    if (inputs.size() == 1) return inputs.front();
    return fmt::format("{} (and {} more input{})", inputs.empty() ? std::string() : inputs.front(), inputs.size() - 1, inputs.size() == 2 ? "" : "s");
}

DenseVolume describeDicomSeries(const std::vector<std::string>& inputs, const std::string& choice) {
    ScanState st = scan(inputs);
    const std::string path = dicomInputName(inputs);
    const DicomScan& sc = st.scan;
    if (sc.series.empty()) {
        if (inputs.size() == 1 && sc.skipped.size() == 1 && sc.skipped.front().compare(0, path.size(), path) == 0 && !fs::is_directory(path))
            throw Error(sc.skipped.front());
        throw Error(fmt::format("{}: holds no DICOM image series; {} file(s) skipped, e.g. {}", path, sc.skipped.size(),
                                sc.skipped.empty() ? std::string("none") : sc.skipped.front()));
    }
    size_t index = 0;
    const std::string c = trim(choice);
    if (c.empty()) {
        if (sc.series.size() > 1)
            throw Error(fmt::format("{}: holds {} series, pick one with --series N or UID: {}", path, sc.series.size(), listing(sc)));
    } else if (c.find_first_not_of("0123456789") == std::string::npos) {
        const unsigned long long n = c.size() > 9 ? 0 : std::stoull(c);
        if (n < 1 || n > sc.series.size())
            throw Error(fmt::format("{}: there is no series {}; it holds {}: {}", path, c, sc.series.size(), listing(sc)));
        index = size_t(n - 1);
    } else {
        std::vector<size_t> matches;
        for (size_t i = 0; i < sc.series.size(); ++i)
            if (sc.series[i].uid == c) matches.push_back(i);
        if (matches.empty()) throw Error(fmt::format("{}: no series has the UID {}; it holds {}: {}", path, c, sc.series.size(), listing(sc)));
        if (matches.size() > 1) {
            std::string list;
            for (size_t i = 0; i < matches.size(); ++i) list += (i ? "; " : "") + oneLine(matches[i], sc.series[matches[i]]);
            throw Error(fmt::format("{}: the series {} is split into {} parts (by orientation or image size), pick one with --series N: {}", path, c,
                                    matches.size(), list));
        }
        index = matches.front();
    }
    const Group& g = st.groups[index];
    if (!g.problem.empty()) throw Error(fmt::format("{}: series {} ({}): {}", path, index + 1, g.info.uid, g.problem));

    DenseVolume v;
    v.format = DenseFormat::Dicom;
    v.headerPath = inputs.front();
    v.dataPath = inputs.front();
    if (inputs.size() > 1)  // a list of files: the grid is named after the first one's folder
        v.gridName = scanNameOf(fs::absolute(inputs.front()).parent_path().filename().string());
    v.dims = g.info.dims;
    v.type = *g.type;
    v.bigEndian = false;
    const Frame& f0 = g.frames.front();
    v.origin = f0.position;
    v.axes[0] = scaled(g.rowDir, f0.columnSpacing);
    v.axes[1] = scaled(g.colDir, f0.rowSpacing);
    const int64_t n = v.dims[2];  // slots, the missing ones included
    v.axes[2] = n > 1 ? scaled(sub(g.frames.back().position, f0.position), 1.0 / double(n - 1)) : scaled(g.normal, f0.thickness > 0 ? f0.thickness : 1.0);
    v.space = "LPS";
    v.rescaleSlope = f0.slope;
    v.rescaleIntercept = f0.intercept;
    if (g.first.bitsStored > 0 && g.first.bitsStored < g.first.bitsAllocated) v.bitsStored = g.first.bitsStored;
    v.slices.assign(size_t(n), DicomSlice{});  // missing slots keep an empty file name
    for (size_t i = 0; i < g.frames.size(); ++i) v.slices[size_t(g.slots[i])] = {g.frames[i].file, g.frames[i].frame};
    v.missingSlices = g.missing;
    for (const std::string& note : g.info.notes) v.notes.push_back(fmt::format("{}: series {}: {}", path, index + 1, note));
    v.headerFields = g.first.tags;
    v.validate();
    return v;
}

namespace {

class DicomSliceReader : public SliceReader {
public:
    explicit DicomSliceReader(const DenseVolume& volume) : v_(volume) {
        v_.validate();
        if (v_.slices.size() != size_t(v_.dims[2]))
            throw Error(fmt::format("{}: the series lists {} slice files for {} slices", v_.headerPath, v_.slices.size(), v_.dims[2]));
        if (!isIntegerSample(v_.type)) throw Error(v_.headerPath + ": float DICOM samples are not supported");
        for (const DicomSlice& s : v_.slices) {
            std::error_code ec;
            if (s.file.empty()) continue;  // a missing slice (no file)
            if (!fs::is_regular_file(s.file, ec)) throw Error(s.file + ": slice file of " + v_.headerPath + " is missing or not a regular file");
        }
    }

    void readSlices(int64_t slices, std::vector<uint8_t>& out) override {
        if (slices < 0 || next_ + slices > v_.dims[2])
            throw Error(fmt::format("{}: asked for slices {} to {} of a series of {}", v_.headerPath, next_, next_ + slices, v_.dims[2]));
        const size_t sliceBytes = size_t(v_.sliceSamples()) * sampleBytes(v_.type);
        out.resize(size_t(slices) * sliceBytes);
        for (int64_t i = 0; i < slices; ++i) decode(v_.slices[size_t(next_ + i)], out.data() + size_t(i) * sliceBytes, sliceBytes);
        next_ += slices;
    }

private:
    void decode(const DicomSlice& slice, uint8_t* out, size_t sliceBytes) {
        if (slice.file.empty()) {  // a missing slice (DenseVolume::missingSlices): no data
            std::memset(out, 0, sliceBytes);
            return;
        }
        if (slice.file != cachedFile_) {
            cachedFile_.clear();
            cache_.clear();
            quietGdcm();
            const std::string where = fmt::format("{}: slice file of {}", slice.file, v_.headerPath);
            detail::DicomPixelData px;
            if (const std::string bad = elementLengthProblem(slice.file, false, nullptr, &px); !bad.empty())
                throw Error(where + ": corrupt DICOM: " + bad);
            cachedFrames_ = px.found && !px.encapsulated && nativeSyntax(px.transferSyntax) ? decodeNative(slice.file, where, px, sliceBytes)
                                                                                           : decodeWithGdcm(slice.file, px.transferSyntax, where, sliceBytes);
            cachedFile_ = slice.file;
        }
        if (slice.frame >= cachedFrames_) throw Error(fmt::format("{}: frame {} is missing", slice.file, slice.frame + 1));
        std::copy_n(cache_.data() + size_t(slice.frame) * sliceBytes, sliceBytes, out);
    }

    // The pixel format a file declares must be the series'.
    void checkFormat(const std::string& where, uint64_t cols, uint64_t rows, unsigned samples, unsigned bits, unsigned representation) const {
        if (int64_t(cols) != v_.dims[0] || int64_t(rows) != v_.dims[1])
            throw Error(fmt::format("{}: holds {}x{} pixels where the series has {}x{}", where, cols, rows, v_.dims[0], v_.dims[1]));
        if (samples != 1) throw Error(fmt::format("{}: holds {} samples per pixel; the series has 1", where, samples));
        const std::optional<SampleType> t = sampleTypeOf(bits, representation);
        if (!t || *t != v_.type)
            throw Error(fmt::format("{}: its pixels decode as {} bits {} (Pixel Representation {}), not the series' {}", where, bits,
                                    representation ? "signed" : "unsigned", representation, sampleTypeName(v_.type)));
    }

    // Native (uncompressed) pixel data, read by vdbdag from where the
    // element walk found them: GDCM parses the header (the walk has checked
    // its structure) but never the pixels, whose reader asserts on forged
    // fields. As GDCM's image reader: the stored values as they are, byte
    // swapped from big-endian, unused high bits cleared (sign-extended when
    // signed) only where an overlay lives in them. Returns the frame count.
    uint64_t decodeNative(const std::string& file, const std::string& where, const detail::DicomPixelData& px, size_t sliceBytes) {
        gdcm::Reader reader;
        reader.SetFileName(file.c_str());
        if (!reader.ReadUpToTag(gdcm::Tag(kPixelGroup, 0x0008), {gdcm::Tag(kPixelGroup, 0x0010)}))
            throw Error(where + ": GDCM cannot read its header (truncated or corrupt?)");
        const gdcm::DataSet& ds = reader.GetFile().GetDataSet();
        const Fields f(reader.GetFile());
        const auto number = [&](uint16_t g, uint16_t e, double fallback) {
            const auto v = f.numbers(ds, g, e);
            return v && v->size() == 1 && (*v)[0] >= 0 && (*v)[0] < 4294967296.0 ? (*v)[0] : fallback;
        };
        const uint64_t cols = uint64_t(number(0x0028, 0x0011, 0)), rows = uint64_t(number(0x0028, 0x0010, 0));
        const unsigned bits = unsigned(number(0x0028, 0x0100, 0)), stored = unsigned(number(0x0028, 0x0101, 0));
        const unsigned representation = unsigned(number(0x0028, 0x0103, 0));
        checkFormat(where, cols, rows, unsigned(number(0x0028, 0x0002, 1)), bits, representation);
        const uint64_t frames = std::max<uint64_t>(1, uint64_t(number(0x0028, 0x0008, 1)));
        if (frames > px.length / sliceBytes)
            throw Error(fmt::format("{}: its pixel data hold {} bytes, fewer than the {} bytes per frame its {} frame(s) need", where, px.length,
                                    sliceBytes, frames));
        cache_.resize(size_t(frames * sliceBytes));
        std::FILE* in = std::fopen(file.c_str(), "rb");
        const bool read = in && std::fseek(in, long(px.offset), SEEK_SET) == 0 && std::fread(cache_.data(), 1, cache_.size(), in) == cache_.size();
        if (in) std::fclose(in);
        if (!read) throw Error(fmt::format("{}: cannot read its {} bytes of pixel data", where, cache_.size()));
        const size_t bytes = sampleBytes(v_.type);
        if (px.bigEndian && bytes > 1)
            for (size_t i = 0; i < cache_.size(); i += bytes) std::reverse(cache_.begin() + long(i), cache_.begin() + long(i + bytes));
        bool overlayInPixels = false;  // (60xx,0010) Overlay Rows without (60xx,3000) Overlay Data
        for (uint16_t g = 0x6000; g <= 0x601e; g += 2)
            overlayInPixels |= ds.FindDataElement(gdcm::Tag(g, 0x0010)) && !ds.FindDataElement(gdcm::Tag(g, 0x3000));
        if (overlayInPixels && stored > 0 && stored < bits) clearUnusedBits(stored, representation != 0);
        return frames;
    }

    void clearUnusedBits(unsigned stored, bool isSigned) {
        const size_t bytes = sampleBytes(v_.type);
        for (size_t i = 0; i < cache_.size(); i += bytes) {
            uint64_t v = 0;
            std::memcpy(&v, cache_.data() + i, bytes);
            v &= (uint64_t(1) << stored) - 1;
            if (isSigned && (v >> (stored - 1) & 1)) v |= ~uint64_t(0) << stored;
            std::memcpy(cache_.data() + i, &v, bytes);
        }
    }

    // Compressed pixel data: GDCM's image reader and codecs, after the
    // fields its reader asserts on are checked. Returns the frame count.
    uint64_t decodeWithGdcm(const std::string& file, const std::string& transferSyntax, const std::string& where, size_t sliceBytes) {
        {
            // RLE: GDCM's image reader decodes the pixel data as it reads
            // the file, so they are read (not decoded) and checked first.
            const bool rle = transferSyntax == detail::kRleSyntax;
            gdcm::Reader header;
            header.SetFileName(file.c_str());
            if (!(rle ? header.Read() : header.ReadUpToTag(gdcm::Tag(kPixelGroup, 0x0008), {gdcm::Tag(kPixelGroup, 0x0010)})))
                throw Error(where + ": GDCM cannot read its header (truncated or corrupt?)");
            if (const std::string bad = rle ? detail::rleProblem(header.GetFile()) : ""; !bad.empty()) throw Error(where + ": " + bad);
            const Fields f(header.GetFile());
            const std::string photometric = f.text(header.GetFile().GetDataSet(), 0x0028, 0x0004);
            if (photometric != "MONOCHROME1" && photometric != "MONOCHROME2")
                throw Error(fmt::format("{}: compressed pixel data with Photometric Interpretation '{}' (a greyscale series needs MONOCHROME1 or MONOCHROME2)",
                                        where, photometric));
        }
        gdcm::ImageReader reader;
        reader.SetFileName(file.c_str());
        if (!reader.Read()) throw Error(where + ": GDCM cannot read it as a DICOM image (truncated or corrupt?)");
        const gdcm::Image& image = reader.GetImage();
        const gdcm::PixelFormat& pf = image.GetPixelFormat();
        const unsigned dimsCount = image.GetNumberOfDimensions();
        const uint64_t frames = dimsCount >= 3 ? image.GetDimension(2) : 1;
        checkFormat(where, image.GetDimension(0), image.GetDimension(1), pf.GetSamplesPerPixel(), pf.GetBitsAllocated(), pf.GetPixelRepresentation());
        const uint64_t length = image.GetBufferLength();
        if (length < frames * sliceBytes)
            throw Error(fmt::format("{}: its pixel data decode to {} bytes, fewer than the {} its {} frame(s) need", where, length, frames * sliceBytes, frames));
        cache_.resize(size_t(length));
        if (!image.GetBuffer(reinterpret_cast<char*>(cache_.data())))
            throw Error(fmt::format("{}: GDCM cannot decode its pixel data (transfer syntax {}; truncated or corrupt?)", where,
                                    reader.GetFile().GetHeader().GetDataSetTransferSyntax().GetString()
                                        ? reader.GetFile().GetHeader().GetDataSetTransferSyntax().GetString()
                                        : "unknown"));
        return frames;
    }

    static bool nativeSyntax(const std::string& uid) {
        // No file meta group (ACR-NEMA style), implicit LE, explicit LE, explicit BE.
        return uid.empty() || uid == "1.2.840.10008.1.2" || uid == "1.2.840.10008.1.2.1" || uid == "1.2.840.10008.1.2.2";
    }

    DenseVolume v_;
    int64_t next_ = 0;
    std::string cachedFile_;  // the last file decoded (a multi-frame file is decoded once)
    std::vector<uint8_t> cache_;
    uint64_t cachedFrames_ = 0;
};

} // namespace

std::unique_ptr<SliceReader> openDicomSlices(const DenseVolume& volume) { return std::make_unique<DicomSliceReader>(volume); }

} // namespace vdbdag::bridge
