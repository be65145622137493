#include "plugin/technique.h"

#include <stdexcept>

namespace rtlab::plugin {

void Registry::addFamily(FamilyInfo family)
{
    if (findFamily(family.name))
        throw std::logic_error("family '" + family.name + "' registered twice");
    mFamilies.push_back(std::move(family));
}

void Registry::addTechnique(TechniqueEntry entry)
{
    if (!findFamily(entry.info.family))
        throw std::logic_error("technique '" + entry.info.name + "' names unknown family '" +
                               entry.info.family + "'");
    if (findTechnique(entry.info.family, entry.info.name))
        throw std::logic_error("technique '" + entry.info.family + "/" + entry.info.name +
                               "' registered twice");
    mTechniques.push_back(std::make_unique<TechniqueEntry>(std::move(entry)));
}

const FamilyInfo* Registry::findFamily(const std::string& name) const
{
    for (const auto& f : mFamilies)
        if (f.name == name)
            return &f;
    return nullptr;
}

const TechniqueEntry* Registry::findTechnique(const std::string& family, const std::string& name) const
{
    for (const auto& t : mTechniques)
        if (t->info.family == family && t->info.name == name)
            return t.get();
    return nullptr;
}

std::vector<std::string> Registry::familyNames() const
{
    std::vector<std::string> names;
    for (const auto& f : mFamilies)
        names.push_back(f.name);
    return names;
}

std::vector<std::string> Registry::techniqueNames(const std::string& family) const
{
    std::vector<std::string> names;
    for (const auto* t : techniques(family))
        names.push_back(t->info.name);
    return names;
}

std::vector<const TechniqueEntry*> Registry::techniques(const std::string& family) const
{
    std::vector<const TechniqueEntry*> out;
    for (const auto& t : mTechniques)
        if (t->info.family == family)
            out.push_back(t.get());
    return out;
}

} // namespace rtlab::plugin
