#include "contact_list.hpp"

namespace dem {

ContactList::ContactList(int count, bool two_sided)
    : key("dem::contacts::key", count), i("dem::contacts::i", count), j("dem::contacts::j", count),
      fs("dem::contacts::fs", count), mr("dem::contacts::mr", count), flags("dem::contacts::flags", count),
      fc("dem::contacts::fc", count), m1("dem::contacts::m1", count),
      m2("dem::contacts::m2", two_sided ? count : 0), fn("dem::contacts::fn", count), n(count) {}

}  // namespace dem
