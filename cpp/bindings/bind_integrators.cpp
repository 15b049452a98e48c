// The C++ integrators: options, the run (GIL released), and batch outputs for results.
#include <limits>
#include <type_traits>
#include <variant>

#include "bindings.hpp"
#include "rigidfem/adjoint.hpp"
#include "rigidfem/auto_method.hpp"
#include "rigidfem/errors.hpp"
#include "rigidfem/integrators.hpp"
#include "rigidfem/outputs.hpp"
#include "rigidfem/parameters.hpp"

namespace rigidfem::bindings {

namespace {
// An option's value as a Python object.
py::object option_value(const OptionValue& v) {
  return std::visit(
      [](const auto& x) -> py::object {
        using T = std::decay_t<decltype(x)>;
        if constexpr (std::is_same_v<T, std::monostate>)
          return py::none();
        else
          return py::cast(x);
      },
      v);
}

// A Python value as the option `info` takes it: None where allowed, else a real number, an integer, True or
// False, a name, or one or more real numbers (the bindings' conversion rules; ValueError naming the option).
OptionValue option_value(const OptionInfo& info, const py::object& x) {
  const std::string name = info.name, expected = info.expected;
  if (x.is_none()) {
    if (info.none_allowed) return std::monostate();
    bad(name, expected, "None");
  }
  switch (info.type) {
    case OptionType::Real: return real_arg(x, name, expected);
    case OptionType::Integer: return static_cast<long>(int_arg(x, name, expected, -(1LL << 62), 1LL << 62));
    case OptionType::Flag:
      if (!PyBool_Check(x.ptr()) && !(py::hasattr(x, "dtype") && std::string(py::str(x.attr("dtype"))) == "bool"))
        bad(name, expected, arg_repr(x));
      return x.cast<bool>();
    case OptionType::Name:
      if (!PyUnicode_Check(x.ptr())) bad(name, expected, arg_repr(x));
      return x.cast<std::string>();
    case OptionType::Reals: {
      const py::array_t<double> a = real_array_arg(x, name, expected);
      if (a.ndim() == 0) return *a.data();
      if (a.ndim() != 1) bad(name, expected, "an array of " + std::to_string(a.ndim()) + " dimensions");
      return std::vector<double>(a.data(), a.data() + a.size());
    }
    case OptionType::Outputs: break;
  }
  bad(name, "an option set by its own converter", arg_repr(x));
}

// The states of a trajectory as the rows of a (len t, n) array.
RowMatX stack(const std::vector<VecX>& rows, int n) {
  RowMatX M(rows.size(), n);
  for (size_t k = 0; k < rows.size(); ++k) M.row(k) = rows[k].transpose();
  return M;
}
// The method's own multipliers at the outputs as (len t, nl) rows, NaN where it has none.
RowMatX multipliers(const std::vector<VecX>& rows, int nl) {
  RowMatX L = RowMatX::Constant(rows.size(), nl, std::numeric_limits<double>::quiet_NaN());
  for (size_t k = 0; k < rows.size(); ++k)
    if (rows[k].size() == nl) L.row(k) = rows[k].transpose();
  return L;
}
}  // namespace

void bind_integrators(py::module_& m) {
  py::class_<IntegratorOptions>(m, "IntegratorOptions",
                                "Options of the C++ integrators (see rigidfem.simulate): each option of the table "
                                "(_option_table) through set and get; the method, s0 and stiff_method as attributes.")
      .def(py::init<>())
      .def_property(
          "method", [](const IntegratorOptions& o) { return method_name(o.method); },
          [](IntegratorOptions& o, const std::string& name) { o.method = parse_method(name); })
      .def_readwrite("s0", &IntegratorOptions::s0, "(nz) the Maxwell arms' initial forces (N or N·m); empty: zero")
      .def(
          "set_error_on",
          [](IntegratorOptions& o, const std::vector<std::tuple<std::string, int, Vec3>>& outputs) {
            // (kind, index, r): "bodies", "point" (body, r), "coordinate" (q index), "element", "loop"
            static const std::pair<const char*, OutputSpec::Kind> kinds[] = {
                {"bodies", OutputSpec::Kind::Bodies}, {"point", OutputSpec::Kind::Point},
                {"coordinate", OutputSpec::Kind::Coordinate}, {"element", OutputSpec::Kind::Element},
                {"loop", OutputSpec::Kind::Loop}};
            o.error_on.clear();
            for (const auto& [kind, index, r] : outputs) {
              OutputSpec spec{OutputSpec::Kind::Bodies, index, r};
              bool known = false;
              for (const auto& [name, k] : kinds)
                if (kind == name) spec.kind = k, known = true;
              if (!known) bad("error_on", "'bodies', 'point', 'coordinate', 'element' or 'loop' outputs", kind);
              o.error_on.push_back(spec);
            }
          },
          py::arg("outputs"), "The outputs the error is measured on: (kind, index, r) each; [] for the state.")
      .def(
          "add_sensitivity",
          [](IntegratorOptions& o, std::shared_ptr<System> plus, std::shared_ptr<System> minus, double h,
             const VecX& S0) { o.sensitivities.push_back({plus, minus, h, S0}); },
          py::arg("plus"), py::arg("minus"), py::arg("h"), py::arg("S0"),
          "A direction of the forward sensitivities: the system at p + h and, for a central difference, at p - h "
          "(None, None: an initial value), and [dq0/dp, dqd0/dp] (2 nq).")
      .def(
          "add_event",
          [](IntegratorOptions& o, const std::string& kind, const std::string& name, int index, const Vec3& r,
             const Vec3& axis, double value, int direction, bool terminal, bool restarts, const py::object& function) {
            // kind: "coordinate", "rate", "point", "contact" or "function" (function(t, q, qd), called with the GIL)
            static const std::pair<const char*, EventSpec::Kind> kinds[] = {
                {"coordinate", EventSpec::Kind::Coordinate}, {"rate", EventSpec::Kind::Rate},
                {"point", EventSpec::Kind::Point}, {"contact", EventSpec::Kind::Contact},
                {"function", EventSpec::Kind::Function}};
            EventSpec e;
            bool known = false;
            for (const auto& [k, value_kind] : kinds)
              if (kind == k) e.kind = value_kind, known = true;
            if (!known) bad("events", "'coordinate', 'rate', 'point', 'contact' or 'function' events", kind);
            e.name = name, e.index = index, e.r = r, e.axis = axis, e.value = value, e.direction = direction;
            e.terminal = terminal, e.restarts = restarts;
            if (!function.is_none()) {
              // the reference is dropped under the GIL wherever the last copy dies
              std::shared_ptr<py::object> f(new py::object(function), [](py::object* x) {
                py::gil_scoped_acquire gil;
                delete x;
              });
              e.function = [f](double t, const VecX& q, const VecX& qd) {
                py::gil_scoped_acquire gil;
                return (*f)(t, q, qd).cast<double>();
              };
            }
            o.events.push_back(std::move(e));
          },
          py::arg("kind"), py::arg("name"), py::arg("index"), py::arg("r"), py::arg("axis"), py::arg("value"),
          py::arg("direction"), py::arg("terminal"), py::arg("restarts"), py::arg("function"),
          "An event of the run (events.hpp): its kind, name, index (coordinate, body or contact), r and axis (a "
          "point's), the value g crosses, direction, terminal, restarts, and function(t, q, qd) for 'function'.")
      .def_property(
          "stiff_method", [](const IntegratorOptions& o) { return method_name(o.stiff_method); },
          [](IntegratorOptions& o, const std::string& name) { o.stiff_method = parse_method(name); })
      .def(
          "set",
          [](IntegratorOptions& o, const std::string& name, const py::object& value) {
            const OptionInfo& info = option_info(name);
            if (!info.set) bad(name, "an option set by its own converter", "'" + name + "'");
            info.set(o, option_value(info, value));
          },
          py::arg("name"), py::arg("value"),
          "Sets the option `name` from a Python value of its type (integrator_options: ValueError naming it otherwise).")
      .def(
          "get", [](const IntegratorOptions& o, const std::string& name) { return option_value(option_info(name).get(o)); },
          py::arg("name"), "The option `name` as Python shows it.");

  m.def(
      "_auto_stiff_method",
      [](const System& s, const std::string& iteration_matrix) {
        IntegratorOptions o;
        o.iteration_matrix = parse_iteration_matrix(iteration_matrix);
        return std::string(method_name(auto_stiff_method(s, o)));
      },
      py::arg("system"), py::arg("iteration_matrix"), "The implicit method method='auto' hands over to.");
  m.def("_measures_outputs", &measures_outputs, py::arg("system"), py::arg("options"),
        "Whether error_on's default for the run is the bodies' displacements (else the state).");
  m.def(
      "_method_table",
      [] {
        py::list rows;
        for (const MethodInfo& m : method_table()) {
          py::list options;
          for (const char* name : m.options) options.append(name);
          rows.append(py::dict(py::arg("name") = m.name, py::arg("family") = m.family, py::arg("order") = m.order,
                               py::arg("error_estimate") = m.error_estimate, py::arg("adaptive") = m.adaptive,
                               py::arg("measures_outputs") = m.measures_outputs, py::arg("adjoint") = m.adjoint,
                               py::arg("options") = options,
                               py::arg("doc") = m.doc));
        }
        return rows;
      },
      "The C++ methods, each a dict: name, family, order (of the propagated solution), error_estimate, adaptive (by\n"
      "default), measures_outputs (error_on's default: the bodies, else the state), adjoint (rigidfem.gradient), options\n"
      "(the names it reads), doc.");
  m.def(
      "_option_table",
      [] {
        static const char* types[] = {"real", "integer", "flag", "name", "reals", "outputs"};
        const IntegratorOptions defaults;
        py::list rows;
        for (const OptionInfo& o : integrator_options())
          rows.append(py::dict(py::arg("name") = o.name, py::arg("type") = types[static_cast<int>(o.type)],
                               py::arg("default") = option_value(o.get(defaults)), py::arg("unit") = o.unit,
                               py::arg("expected") = o.expected, py::arg("doc") = o.doc,
                               py::arg("none_allowed") = o.none_allowed));
        return rows;
      },
      "The options of the integrators, each a dict: name, type, default, unit, doc, none_allowed.");
  m.def("_check_options", &check_options, py::arg("system"), py::arg("t0"), py::arg("t_end"), py::arg("q0"),
        py::arg("qd0"), py::arg("t_eval"), py::arg("options"),
        "integrate's checks of the options alone (ValueError naming the first bad one).");
  m.def(
      "_integrate",
      [](const System& s, double t0, double t_end, const VecX& q0, const VecX& qd0,
         const Eigen::Ref<const VecX>& t_eval, const IntegratorOptions& o, py::object keep_going) {
        // Runs with the GIL released; every ~0.05 s the monitor takes it back to look for
        // Ctrl-C (PyErr_CheckSignals, main thread) and to ask keep_going(t) (progress, stop event).
        Monitor monitor = [&keep_going](double t) {
          py::gil_scoped_acquire gil;
          if (PyErr_CheckSignals() != 0) {
            PyErr_Clear();
            return false;
          }
          return keep_going.is_none() || keep_going(t).cast<bool>();
        };
        Trajectory tr;
        {
          py::gil_scoped_release release;
          tr = integrate(s, t0, t_end, q0, qd0, t_eval, o, monitor);
        }
        // A run ended early: Ctrl-C in a Python callback returns the partial result; a numerical
        // failure returns it with the error's message (Python raises SimulationError carrying it);
        // any other exception propagates.
        py::object failure = py::none();
        if (tr.error) {
          try {
            std::rethrow_exception(tr.error);
          } catch (py::error_already_set& e) {
            if (!e.matches(PyExc_KeyboardInterrupt)) throw;
            tr.interrupted = true;
          } catch (const SimulationError& e) {
            failure = py::make_tuple(e.what(), e.time, e.cause);
          }
        }
        const auto& st = tr.stats;
        py::dict stats;
        stats["method"] = st.method;
        stats["steps"] = st.steps;
        stats["rejected_steps"] = st.rejected;
        stats["rhs_evaluations"] = st.rhs_evaluations;
        stats["jacobians"] = st.jacobians;
        stats["factorizations"] = st.factorizations;
        stats["newton_iterations"] = st.newton_iterations;
        stats["linear_iterations"] = st.linear_iterations;
        stats["wall_time"] = st.wall_time;
        stats["stiff_at"] = st.stiff_at;
        stats["switched_at"] = st.switched_at;
        stats["auto_trials"] = st.auto_trials;
        stats["omega_max"] = st.omega_max;
        stats["probe_steps"] = st.probe_steps;
        stats["model_size"] = st.model_size;
        stats["event_restarts"] = st.event_restarts;
        py::list events;  // (event, t, direction, y, dt/dp) each
        for (const EventRecord& e : tr.events) events.append(py::make_tuple(e.event, e.t, e.direction, e.y, e.dt_dp));
        return py::make_tuple(VecX(Eigen::Map<const VecX>(tr.t.data(), tr.t.size())), stack(tr.q, s.nq),
                              stack(tr.qd, s.nq), stats, tr.interrupted, failure, stack(tr.s, s.nz),
                              multipliers(tr.lambda, s.nl),
                              stack(tr.sensitivities, 2 * s.nq * static_cast<int>(o.sensitivities.size())), events);
      },
      py::arg("system"), py::arg("t0"), py::arg("t_end"), py::arg("q0"), py::arg("qd0"), py::arg("t_eval"),
      py::arg("options"), py::arg("keep_going"));

  // The adjoint (adjoint.hpp): one forward run, then backward sweeps; Ctrl-C stops either (the GIL is held).
  static const auto check_signals = [] {
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
  };
  py::class_<Adjoint>(m, "_Adjoint")
      .def(py::init([](std::shared_ptr<const System> s, const IntegratorOptions& o,
                       const std::vector<std::tuple<std::string, int, Vec3>>& outputs, double memory) {
             std::vector<OutputSpec> specs;
             for (const auto& [kind, index, r] : outputs) {
               if (kind != "point" && kind != "coordinate") bad("outputs", "points and coordinates", kind);
               specs.push_back({kind == "point" ? OutputSpec::Kind::Point : OutputSpec::Kind::Coordinate, index, r});
             }
             return std::make_unique<Adjoint>(s, o, specs, memory);
           }),
           py::arg("system"), py::arg("options"), py::arg("outputs"), py::arg("memory"))
      .def(
          "forward",
          [](Adjoint& a, double t0, double t_end, const VecX& q0, const VecX& qd0) {
            InterruptScope interrupt(check_signals);
            a.forward(t0, t_end, q0, qd0);
            return py::make_tuple(VecX(Eigen::Map<const VecX>(a.times().data(), a.times().size())), a.outputs());
          },
          py::arg("t0"), py::arg("t_end"), py::arg("q0"), py::arg("qd0"), "(t (N + 1), y (N + 1, K)) of the run.")
      .def(
          "backward",
          [](Adjoint& a, const Eigen::Ref<const RowMatX>& ybar) {
            InterruptScope interrupt(check_signals);
            VecX grad = a.backward(ybar);
            const AdjointStats& st = a.stats();
            py::dict stats;
            stats["steps"] = st.steps;
            stats["recomputed_steps"] = st.recomputed_steps;
            stats["checkpoints"] = st.checkpoints;
            stats["checkpoint_interval"] = st.interval;
            stats["linear_iterations"] = st.linear_iterations;
            stats["preconditioner_refreshes"] = st.preconditioner_refreshes;
            stats["forward_time"] = st.forward_time;
            stats["backward_time"] = st.backward_time;
            return py::make_tuple(grad, a.q0bar(), a.qd0bar(), stats);
          },
          py::arg("ybar"), "(dJ/dp, dJ/dq0, dJ/dqd0, stats) for ybar = dJ/dy (N + 1, K).");

  // Outputs over a result's times; Ctrl-C stops them (KeyboardInterrupt).
  m.def(
      "_evaluate_outputs",
      [](const System& s, const Eigen::Ref<const VecX>& t, const Eigen::Ref<const RowMatX>& Q,
         const Eigen::Ref<const RowMatX>& QD, const Eigen::Ref<const RowMatX>& S, const Eigen::Ref<const RowMatX>& L) {
        InterruptScope interrupt(check_signals);
        StateOutputs o = evaluate_outputs(s, t, Q, QD, S, L);
        return py::make_tuple(o.qdd, o.tau, o.kinetic, o.gravity, o.elastic, o.power, o.reactions, o.element_forces);
      },
      py::arg("system"), py::arg("t"), py::arg("q"), py::arg("qd"), py::arg("s"), py::arg("lambda_"));
  m.def(
      "_point_positions",
      [](const System& s, int body, const Vec3& r, int frame, const Eigen::Ref<const VecX>& t,
         const Eigen::Ref<const RowMatX>& Q) {
        InterruptScope interrupt(check_signals);
        return point_positions(s, body, r, frame, t, Q);
      },
      py::arg("system"), py::arg("body"), py::arg("r"), py::arg("frame"), py::arg("t"), py::arg("q"));
  m.def(
      "_body_poses",
      [](const System& s, const Eigen::Ref<const VecX>& t, const Eigen::Ref<const RowMatX>& Q) {
        InterruptScope interrupt(check_signals);
        return body_poses(s, t, Q);
      },
      py::arg("system"), py::arg("t"), py::arg("q"),
      "(len(t) nbodies, 12): each body's rotation row by row and origin (m) at each (t_k, q_k).");
}

}  // namespace rigidfem::bindings
