// SPDX-License-Identifier: MIT
// Private to the pipeline: its plugin instances, one list per wrapper type (Source,
// Matcher, CloudTransform, an evaluator's slot, a new kind's wrapper). It names no kind,
// so a new plugin kind adds no member here or in pipeline.hpp: pipeline.cpp makes its
// instances, pipeline_stages.cpp calls them (docs/DEVELOPING.md, "A new plugin kind").
#pragma once

#include <memory>
#include <typeindex>
#include <typeinfo>
#include <vector>

namespace binocle {

class PluginInstances {
public:
    template <class T> using List = std::vector<std::unique_ptr<T>>;

    PluginInstances() = default;
    PluginInstances(const PluginInstances &) = delete;
    PluginInstances &operator=(const PluginInstances &) = delete;
    // The lists go in the reverse order of their making, as members would: the pipeline
    // makes the source's first, so a source outlives every other instance.
    ~PluginInstances() {
        while (!lists_.empty()) lists_.pop_back();
    }

    // T's instances, to fill or replace; the list is made (empty) the first time. Only
    // where no stage runs: the pipeline's constructor and reconfigure().
    template <class T> List<T> &edit() {
        if (List<T> *found = find<T>()) return *found;
        auto made = std::make_unique<ListOf<T>>();
        List<T> &items = made->items;
        lists_.push_back(std::move(made));
        return items;
    }
    // T's instances, from any thread; an empty list when the rig has none of them
    // (nothing is made here: the stage threads only read).
    template <class T> const List<T> &of() const {
        static const List<T> none;
        const List<T> *found = find<T>();
        return found ? *found : none;
    }

private:
    struct AnyList {
        explicit AnyList(std::type_index t) : type(t) {}
        virtual ~AnyList() = default;
        std::type_index type;
    };
    template <class T> struct ListOf : AnyList {
        ListOf() : AnyList(typeid(T)) {}
        List<T> items;
    };
    // A few lists (one per kind): a linear search.
    template <class T> List<T> *find() const {
        for (const std::unique_ptr<AnyList> &l : lists_)
            if (l->type == std::type_index(typeid(T))) return &static_cast<ListOf<T> &>(*l).items;
        return nullptr;
    }

    std::vector<std::unique_ptr<AnyList>> lists_; // in the order they were made
};

} // namespace binocle
