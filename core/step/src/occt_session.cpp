#include "occt_session.hpp"

#include <Message.hxx>
#include <Message_Messenger.hxx>
#include <Message_Printer.hxx>
#include <Message_PrinterOStream.hxx>
#include <TCollection_AsciiString.hxx>

namespace lamina::step_detail {
namespace {

std::mutex g_messenger_mutex;

struct Store {
  std::mutex mutex;
  std::vector<CaughtMessages::Message> messages;
  std::map<std::string, std::size_t> index;
};
Store g_store;

class StorePrinter : public Message_Printer {
 public:
  DEFINE_STANDARD_RTTI_INLINE(StorePrinter, Message_Printer)
  StorePrinter() { SetTraceLevel(Message_Warning); }

 protected:
  void send(const TCollection_AsciiString& text, const Message_Gravity gravity) const override {
    if (gravity < Message_Warning) return;
    std::string line(text.ToCString());
    while (!line.empty() && (line.back() == '\n' || line.back() == '\r' || line.back() == ' ')) line.pop_back();
    if (line.empty()) return;
    std::lock_guard lock(g_store.mutex);
    auto [it, fresh] = g_store.index.emplace(line, g_store.messages.size());
    if (fresh) g_store.messages.push_back({line, gravity, 0});
    ++g_store.messages[it->second].count;
  }
};

}  // namespace

CaughtMessages::CaughtMessages() : lock_(g_messenger_mutex) {
  const Handle(Message_Messenger)& messenger = ::Message::DefaultMessenger();
  messenger->RemovePrinters(STANDARD_TYPE(Message_PrinterOStream));
  messenger->RemovePrinters(STANDARD_TYPE(StorePrinter));
  messenger->AddPrinter(new StorePrinter());
  std::lock_guard lock(g_store.mutex);
  g_store.messages.clear();
  g_store.index.clear();
}

CaughtMessages::~CaughtMessages() { ::Message::DefaultMessenger()->RemovePrinters(STANDARD_TYPE(StorePrinter)); }

std::vector<CaughtMessages::Message> CaughtMessages::messages() const {
  std::lock_guard lock(g_store.mutex);
  return g_store.messages;
}

}  // namespace lamina::step_detail
