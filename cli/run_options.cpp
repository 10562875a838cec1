#include "run_options.hpp"

namespace lidarloop::cli {

void RunOptionFlags::AddTo(CLI::App& command, app::RunCommand which) {
    using T = app::RunOptionType;
    for (const app::RunOption* option : app::RunOptionsOf(which)) {
        Slot& slot = slots_.emplace_back();
        slot.option = option;
        const std::string flag(option->flag);
        const std::string help(option->help);
        switch (option->type) {
            case T::kInt:
                slot.flag = command.add_option(flag, slot.integer, help);
                break;
            case T::kNumber:
                slot.flag = command.add_option(flag, slot.number, help);
                break;
            case T::kName:
                slot.flag = command.add_option(flag, slot.name, help);
                break;
            case T::kNumbers:
                slot.flag = command.add_option(flag, slot.numbers, help)->delimiter(',');
                break;
            case T::kSwitch:
            case T::kSwitchOff:
                // A switch takes no value: "--no-verify=false" would still turn verification off.
                slot.flag = command.add_flag(flag, slot.on, help)->disable_flag_override();
                break;
        }
        if (!option->value_name.empty()) slot.flag->type_name(std::string(option->value_name));
    }
}

void RunOptionFlags::ApplyTo(const app::RunTargets& targets) const {
    using T = app::RunOptionType;
    // First the config as the file left it, so that an error of the file is not a flag's.
    targets.config->Validate();
    for (const Slot& slot : slots_) {
        if (!*slot.flag) continue;
        app::RunOptionValue value;
        switch (slot.option->type) {
            case T::kInt:
                value = slot.integer;
                break;
            case T::kNumber:
                value = slot.number;
                break;
            case T::kName:
                value = slot.name;
                break;
            case T::kNumbers:
                value = slot.numbers;
                break;
            case T::kSwitch:
                value = true;
                break;
            case T::kSwitchOff:
                value = false;
                break;
        }
        app::ApplyRunOption(*slot.option, value, targets, /*by_keyword=*/false);
    }
}

}  // namespace lidarloop::cli
