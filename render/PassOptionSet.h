#pragma once
// The options of passes whose options struct lives only in their own folder (Falcor's per-pass
// Properties): one value per struct type, each the struct's defaults until a knob or a caller
// sets it. A pass added to the renderer keeps its options here, so adding it changes no central
// list (RendererOptions names only the frame-wide settings and the passes that predate this set).
// An options struct T must be copyable and default-constructible, with `void validate() const`
// throwing mirage::Error naming the field out of range (render/PassOptions.h's checkOption).
#include <any>
#include <functional>
#include <map>
#include <typeindex>

namespace mirage::render {

class PassOptionSet {
public:
    // The pass's options, created with their defaults on first use.
    template <class T>
    T& get() {
        auto it = values_.find(typeid(T));
        if (it == values_.end())
            it = values_
                     .emplace(typeid(T), Entry{T{},
                                               [](const std::any& v) {
                                                   std::any_cast<const T&>(v).validate();
                                               }})
                     .first;
        return std::any_cast<T&>(it->second.value);
    }
    // The pass's options as set, or their defaults when nothing set them.
    template <class T>
    const T& get() const {
        static const T defaults{};
        const auto it = values_.find(typeid(T));
        return it == values_.end() ? defaults : std::any_cast<const T&>(it->second.value);
    }
    // Validates every options struct that was set (the defaults are valid by construction).
    void validate() const {
        for (const auto& [type, entry] : values_) entry.validate(entry.value);
    }

private:
    struct Entry {
        std::any value;
        std::function<void(const std::any&)> validate;
    };
    std::map<std::type_index, Entry> values_;
};

}  // namespace mirage::render
