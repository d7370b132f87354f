// A coder's models, kept by each thread from one walk to the next and
// restarted in place (T::restart() must leave them exactly as a new T):
// building them anew cost a small walk more than the walk itself (the
// integer coder's 1.9 MB of generation-4 models, the float coder's 300 KB,
// allocated, faulted in and cleared per window; the fuzz targets, whose
// inputs are small, spent a third to a half of their time there). Slots
// keep apart models of different shapes (the integer coder's generations).
// A walk started while another on the same thread holds the slot's models
// (a walk nested in another) builds its own.
#pragma once
#include <array>
#include <cstddef>
#include <memory>
#include <utility>

namespace vdbdag::coding::detail {

template <typename T, size_t Slots = 1>
class ThreadLease {
public:
    // `args` build a new T where this thread has none in `slot` yet, or
    // where another walk holds it.
    template <typename... Args>
    explicit ThreadLease(size_t slot, Args&&... args) {
        Kept& kept = keptModels()[slot];
        if (kept.busy) {
            own_ = std::make_unique<T>(std::forward<Args>(args)...);
            models_ = own_.get();
            return;
        }
        if (kept.models) kept.models->restart();
        else kept.models = std::make_unique<T>(std::forward<Args>(args)...);
        kept.busy = true;
        models_ = kept.models.get();
        kept_ = &kept;
    }
    ~ThreadLease() {
        if (kept_) kept_->busy = false;
    }
    ThreadLease(const ThreadLease&) = delete;
    ThreadLease& operator=(const ThreadLease&) = delete;
    T& operator*() const { return *models_; }
    T* operator->() const { return models_; }

private:
    struct Kept {
        std::unique_ptr<T> models;
        bool busy = false;
    };
    static std::array<Kept, Slots>& keptModels() {
        thread_local std::array<Kept, Slots> kept;
        return kept;
    }
    std::unique_ptr<T> own_;
    T* models_ = nullptr;
    Kept* kept_ = nullptr;
};

} // namespace vdbdag::coding::detail
