// Joint, Body, Point, Load and Model. The friendly keyword API lives in
// rigidfem/model.py; these are the primitives it calls.
#include "bindings.hpp"
#include "rigidfem/model.hpp"
#include "rigidfem/system.hpp"

namespace rigidfem::bindings {

void bind_model(py::module_& m) {
  py::class_<Joint>(m, "JointSpec", "Active coordinates of a joint with their springs and dampers.")
      .def(py::init([](const std::string& kind, const std::vector<std::string>& coordinates) {
             std::vector<Axis> axes;
             for (const auto& c : coordinates) axes.push_back(parse_coordinate(c, "coordinates"));
             return Joint::make(kind, axes);
           }),
           py::arg("kind"), py::arg("coordinates"))
      .def_readonly("kind", &Joint::kind)
      .def_property_readonly("coordinates",
                             [](const Joint& j) {
                               std::vector<std::string> names;
                               for (Axis a : j.axes) names.push_back(axis_name(a));
                               return names;
                             })
      .def_readwrite("stiffness", &Joint::stiffness)
      .def_readwrite("rest", &Joint::rest)
      .def_readwrite("damping", &Joint::damping)
      .def_readwrite("linear", &Joint::linear, "The book's linear model: T = [[1 + S(phi), r], [0, 1]].")
      .def_property_readonly("ncoords", &Joint::ncoords)
      .def(
          "add_coupling", [](Joint& j, int body, int slot, const Mat4& G) { j.coupled.push_back({body, slot, G}); },
          py::arg("body"), py::arg("slot"), py::arg("G"),
          "Let coordinate `slot` of an earlier body (index) also move this linear joint, with generator G (4, 4)\n"
          "in this joint's frame: T = 1 + sum G q (used by the linear model of beams).");

  py::class_<Body>(m, "Body", "Handle of a body of a Model (index -1 is the ground).")
      .def(py::init<>(), "The ground.")
      .def(py::init([](int index, const std::string& name) { return Body{index, name}; }), py::arg("index"),
           py::arg("name"))
      .def_readonly("index", &Body::index)
      .def_readonly("name", &Body::name)
      .def(
          "point", [](const Body& b, const Vec3& r) { return Point(b.index, r); }, py::arg("r"),
          "The material point at r (m, body frame).")
      .def_property_readonly("origin", [](const Body& b) { return Point(b); }, "The point at the body frame's origin.")
      .def("__repr__", [](const Body& b) { return "<rigidfem Body '" + b.name + "' #" + std::to_string(b.index) + ">"; });

  py::class_<Point>(m, "Point", "A material point: body index and position r (m) in the body frame.")
      .def(py::init<int, const Vec3&>(), py::arg("body"), py::arg("r"))
      .def(py::init<const Body&>(), py::arg("body"))
      .def_readonly("body", &Point::body)
      .def_readonly("r", &Point::r);
  py::implicitly_convertible<Body, Point>();

  m.def("pseudo_inertia", &pseudo_inertia, py::arg("mass"), py::arg("com"), py::arg("inertia"),
        "Pseudo-inertia H = int r r^T dm (4, 4) of a body: mass (kg), centre of mass com (3,) m and\n"
        "inertia tensor (3, 3) about the centre of mass (kg m^2), all in the body frame.");

  py::class_<Model>(m, "_Model")
      .def(py::init<const Vec3&>(), py::arg("gravity"))
      .def("_add_body", &Model::add_body, py::arg("name"), py::arg("parent"), py::arg("joint"), py::arg("placement"),
           py::arg("mass"), py::arg("com"), py::arg("inertia"))
      .def("_prescribe", &Model::prescribe, py::arg("body"), py::arg("coordinate"), py::arg("motion"))
      .def("_add_generalized_force", &Model::add_generalized_force, py::arg("body"), py::arg("coordinate"),
           py::arg("value"), py::arg("law"))
      .def(
          "_add_load",
          [](Model& model, int body, const Vec3& point, const Vec3& force, const Vec3& torque, bool follower,
             ProfilePtr scale) { model.add_load({body, point, force, torque, follower, std::move(scale)}); },
          py::arg("body"), py::arg("point"), py::arg("force"), py::arg("torque"), py::arg("follower"),
          py::arg("scale"))
      .def(
          "_add_loop",
          [](Model& model, const std::string& name, const std::string& kind, int a, const Mat4& frame_a, int b,
             const Mat4& frame_b, double length, ProfilePtr drive) {
            return model.add_loop({name, parse_loop_kind(kind, "kind"), a, b, frame_a, frame_b, length, std::move(drive)});
          },
          py::arg("name"), py::arg("kind"), py::arg("a"), py::arg("frame_a"), py::arg("b"), py::arg("frame_b"),
          py::arg("length"), py::arg("drive"))
      .def("_body_index", &Model::body_index, py::arg("name"))
      .def("_coordinate_index", &Model::coordinate_index, py::arg("body"), py::arg("coordinate"))
      .def_property("gravity", &Model::gravity, &Model::set_gravity, "Gravitational acceleration (m/s^2), global.")
      .def_property_readonly("nbodies", [](const Model& model) { return model.bodies().size(); })
      .def_property_readonly("body_names", [](const Model& model) {
        std::vector<std::string> names;
        for (const auto& b : model.bodies()) names.push_back(b.name);
        return names;
      });
}

}  // namespace rigidfem::bindings
