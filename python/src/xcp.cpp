// lash._xcp: the XCP-on-CAN master (can/xcp_client.hpp) over an A2L file, for scripts and the
// live console. Conversion only; bus waits run without the GIL.
#include <chrono>
#include <memory>

#include "convert.hpp"
#include "lash/can/bus.hpp"
#include "lash/can/xcp_a2l.hpp"
#include "lash/can/xcp_client.hpp"

namespace lash::py {
namespace {
namespace xcp = can::xcp;

class Client {
 public:
  Client(const std::string& a2l, const std::string& bus, double timeout_ms)
      : a2l_(xcp::read_a2l(a2l)), file_(a2l), bus_(can::open_bus(bus)) {
    bus_->set_filters({{a2l_.info.res_id, 0x7FF, false}});
    client_ = std::make_unique<xcp::Client>(*bus_, a2l_.info.cmd_id, a2l_.info.res_id,
                                            std::chrono::milliseconds(static_cast<long>(timeout_ms)));
    pyb::gil_scoped_release nogil;
    client_->connect();
  }
  double get(const std::string& name) {
    const xcp::Object& o = object(name);
    pyb::gil_scoped_release nogil;
    return client_->read(o);
  }
  double set(const std::string& name, double value) {
    const xcp::Object& o = object(name);
    if (o.kind != xcp::Kind::characteristic)
      throw InputError(file_, 0, name, "a MEASUREMENT cannot be written; CHARACTERISTICs can");
    pyb::gil_scoped_release nogil;
    client_->write(o, value);
    return client_->read(o);
  }
  pyb::dict daq(const std::vector<std::string>& names, double duration_s) {
    std::vector<xcp::Object> objs;
    for (const auto& n : names) objs.push_back(object(n));
    std::vector<std::vector<double>> cols(objs.size() + 1);
    {
      pyb::gil_scoped_release nogil;
      client_->start_daq(objs);
      const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(duration_s);
      while (std::chrono::steady_clock::now() < end)
        if (auto s = client_->next_sample(std::chrono::milliseconds(50))) {
          cols[0].push_back(s->timestamp_us);
          for (std::size_t i = 0; i < objs.size(); ++i) cols[i + 1].push_back(s->values[i]);
        }
      client_->stop_daq();
    }
    pyb::dict d;
    d["timestamp_us"] = to_array(cols[0]);
    for (std::size_t i = 0; i < objs.size(); ++i) d[pyb::str(names[i])] = to_array(cols[i + 1]);
    return d;
  }
  std::string epk() {
    pyb::gil_scoped_release nogil;
    return client_->get_id(xcp::kIdEpk);
  }
  pyb::list names() const {
    pyb::list l;
    for (const auto& o : a2l_.objects) l.append(o.name);
    return l;
  }
  void close() {
    if (!client_) return;
    try {
      client_->disconnect();
    } catch (const std::exception&) {
    }
    client_.reset();
  }

 private:
  const xcp::Object& object(const std::string& name) {
    if (!client_) throw InputError(file_, 0, name, "the client is closed");
    for (const auto& o : a2l_.objects)
      if (o.name == name) return o;
    throw InputError(file_, 0, name, "no MEASUREMENT or CHARACTERISTIC of that name");
  }
  static pyb::array_t<double> to_array(const std::vector<double>& v) {
    pyb::array_t<double> a(static_cast<pyb::ssize_t>(v.size()));
    std::copy(v.begin(), v.end(), a.mutable_data());
    return a;
  }
  xcp::A2lFile a2l_;
  std::string file_;
  std::unique_ptr<can::Bus> bus_;
  std::unique_ptr<xcp::Client> client_;
};

}  // namespace

void bind_xcp(pyb::module_& root) {
  auto m = root.def_submodule("_xcp", "XCP-on-CAN master (use lash.xcp)");
  pyb::class_<Client>(m, "Client",
                      "Client(a2l, bus='udp:239.74.163.2:43113', timeout_ms=500): connects (XCP CONNECT) to the ECU\n"
                      "the A2L describes (lash hil a2l), on its XCP_ON_CAN ids. Errors: lash.InputError for an\n"
                      "unknown name, RuntimeError for an error packet (its name, e.g. ERR_OUT_OF_RANGE) or a timeout.")
      .def(pyb::init<const std::string&, const std::string&, double>(), pyb::arg("a2l"),
           pyb::arg("bus") = "udp:239.74.163.2:43113", pyb::arg("timeout_ms") = 500.0)
      .def("get", &Client::get, pyb::arg("name"), "get(name) -> float: the object's value (SET_MTA + UPLOAD)")
      .def("set", &Client::set, pyb::arg("name"), pyb::arg("value"),
           "set(name, value) -> float: writes a CHARACTERISTIC in one block (refused outside its A2L limits), "
           "returns the value read back")
      .def("daq", &Client::daq, pyb::arg("names"), pyb::arg("duration_s"),
           "daq(names, duration_s) -> dict name -> numpy array, plus 'timestamp_us': one sample per control step")
      .def("epk", &Client::epk, "the ECU's EPK (GET_ID type 5)")
      .def_property_readonly("names", &Client::names, "the A2L's MEASUREMENT and CHARACTERISTIC names")
      .def("close", &Client::close, "DISCONNECT")
      .def("__enter__", [](Client& c) -> Client& { return c; }, pyb::return_value_policy::reference)
      .def("__exit__", [](Client& c, const pyb::args&) { c.close(); });
}

}  // namespace lash::py
