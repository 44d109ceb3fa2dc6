// Built only by the scheduler_undeclared_* tests, once per CASE: a system that reaches a member of the world
// it did not declare must not compile, with the scheduler's message (cases 1 to 4); case 0, the same system
// declared, compiles.
#include "engine/scheduler.hpp"

namespace {

struct Toy {
  int mesh = 0;
  int requests = 0;
};

}  // namespace

int main() {
  Toy t;
#if CASE == 0
  const fire::SystemSpec s = fire::declare_system<fire::Read<&Toy::mesh>, fire::Write<&Toy::requests>>(
      t, "declared", [](const int& mesh, int& requests) { requests = mesh; });
#elif CASE == 1  // writes a member declared as a read
  const fire::SystemSpec s =
      fire::declare_system<fire::Read<&Toy::mesh>>(t, "writes_a_read", [](int& mesh) { mesh = 1; });
#elif CASE == 2  // reaches an undeclared member through the world it captured
  const fire::SystemSpec s =
      fire::declare_system<fire::Read<&Toy::mesh>>(t, "captures", [&t](const int&) { t.requests = 1; });
#elif CASE == 3  // takes a member it did not declare
  const fire::SystemSpec s = fire::declare_system<fire::Read<&Toy::mesh>>(t, "takes_more", [](const int&, int&) {});
#elif CASE == 4  // writes through a previous-frame read
  const fire::SystemSpec s =
      fire::declare_system<fire::ReadPrevious<&Toy::mesh>>(t, "writes_the_past", [](int& mesh) { mesh = 1; });
#endif
  s.run();
  return t.requests;
}
