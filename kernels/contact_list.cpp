#include "contact_list.hpp"

namespace dem {

ContactList::ContactList(int count)
    : key("dem::contacts::key", count), i("dem::contacts::i", count), j("dem::contacts::j", count),
      fs("dem::contacts::fs", count), mr("dem::contacts::mr", count), flags("dem::contacts::flags", count),
      slip("dem::contacts::slip", count),
      fc("dem::contacts::fc", count), mo("dem::contacts::mo", count), mt("dem::contacts::mt", count), fn("dem::contacts::fn", count), n(count) {}

}  // namespace dem
