// An encoder's range coding on a thread of its own beside the walk that
// predicts (IntCoderOptions::codeAside; FloatValueCoder's windows): the
// walk hands over what each sample codes (its residual and the models that
// code it) in chunks, and the thread codes them in order into one stream.
// The same bytes as coding each sample in turn, so whether a coder runs
// aside is a matter of speed alone: an encoder that would otherwise leave
// a core idle (a grid of one or two windows, a scan's last window) takes
// two. The bit models must be the coding thread's alone: the walks read
// only what the samples left (fits, bias cells, errors), never a model.
// Decoding cannot run so: each prediction needs the sample before it.
#pragma once
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <exception>
#include <functional>
#include <mutex>
#include <span>
#include <thread>
#include <vector>

#include "src/coding/RangeCoder.h"

namespace vdbdag::coding {

// Below this many samples a coder codes in the walk's thread (a thread's
// start costs more than it saves).
inline constexpr size_t kCodeAsideSamples = size_t(1) << 16;

template <typename Item>
class CodeAside {
public:
    // `code(rc, items)` codes the items in order, on the thread; the stream
    // goes to the end of `out`, which is the thread's until finish().
    using Code = std::function<void(RangeEncoder&, std::span<const Item>)>;
    CodeAside(std::vector<uint8_t>& out, Code code) : code_(std::move(code)), thread_([this, &out] { run(out); }) { chunk_.reserve(kChunk); }
    CodeAside(const CodeAside&) = delete;
    CodeAside& operator=(const CodeAside&) = delete;
    ~CodeAside() {
        if (!thread_.joinable()) return;
        {  // left by an exception in the walk: stop the thread; the output is dropped
            std::lock_guard lock(mutex_);
            done_ = abort_ = true;
        }
        ready_.notify_all();
        thread_.join();
    }
    void push(const Item& item) {
        chunk_.push_back(item);
        if (chunk_.size() == kChunk) hand();
    }
    // Codes what is left and ends the stream; rethrows the thread's failure.
    void finish() {
        hand();
        {
            std::lock_guard lock(mutex_);
            done_ = true;
        }
        ready_.notify_all();
        thread_.join();
        if (failure_) std::rethrow_exception(failure_);
    }

private:
    static constexpr size_t kChunk = 8192, kInFlight = 4;
    void hand() {
        if (chunk_.empty()) return;
        std::vector<Item> next;
        {
            std::unique_lock lock(mutex_);
            room_.wait(lock, [&] { return full_.size() < kInFlight || abort_; });
            full_.push_back(std::move(chunk_));
            if (!spare_.empty()) next = std::move(spare_.back()), spare_.pop_back();
        }
        ready_.notify_one();
        chunk_ = std::move(next);
        chunk_.reserve(kChunk);
    }
    void run(std::vector<uint8_t>& out) {
        try {
            RangeEncoder rc(out);
            for (;;) {
                std::vector<Item> c;
                {
                    std::unique_lock lock(mutex_);
                    ready_.wait(lock, [&] { return !full_.empty() || done_; });
                    if (abort_ || full_.empty()) break;
                    c = std::move(full_.front());
                    full_.pop_front();
                }
                room_.notify_one();
                code_(rc, c);
                c.clear();
                std::lock_guard lock(mutex_);
                spare_.push_back(std::move(c));
            }
            std::lock_guard lock(mutex_);
            if (!abort_) rc.finish();
        } catch (...) {
            std::lock_guard lock(mutex_);
            failure_ = std::current_exception();
            abort_ = true;
            room_.notify_all();
        }
    }
    Code code_;
    std::vector<Item> chunk_;
    std::mutex mutex_;
    std::condition_variable ready_, room_;
    std::deque<std::vector<Item>> full_;
    std::vector<std::vector<Item>> spare_;
    bool done_ = false, abort_ = false;
    std::exception_ptr failure_;
    std::thread thread_;  // last: started once the rest is built
};

} // namespace vdbdag::coding
