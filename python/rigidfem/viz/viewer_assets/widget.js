// The notebook widget (anywidget): the viewer's page in an iframe, its frame synchronised with the
// Python side's `frame` (set it from Python to move the slider; moving the slider sets it).
function render({ model, el }) {
  const frame = document.createElement("iframe");
  frame.style.width = "100%";
  frame.style.border = "0";
  frame.style.height = model.get("height") + 40 + "px";
  frame.srcdoc = model.get("page");
  el.appendChild(frame);
  const send = () => frame.contentWindow && frame.contentWindow.postMessage({ rigidfem: "frame", frame: model.get("frame") }, "*");
  model.on("change:frame", send);
  frame.addEventListener("load", send);
  const listen = (e) => {
    if (e.source === frame.contentWindow && e.data && e.data.rigidfem === "shown" && e.data.frame !== model.get("frame")) {
      model.set("frame", e.data.frame);
      model.save_changes();
    }
  };
  window.addEventListener("message", listen);
  return () => window.removeEventListener("message", listen);
}
export default { render };
