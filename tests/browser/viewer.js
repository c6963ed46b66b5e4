// Neuroglancer's default viewer, with its state in the URL hash ("#!" followed by the JSON
// state), as on Neuroglancer's own site: a state that opens a surftrack output there opens it
// here too (docs/cli.md, "Neuroglancer output"). The viewer is window.viewer, which the test
// polls (viewer.isReady(): every visible layer's chunks loaded and drawn).
import "neuroglancer";
import { setupDefaultViewer } from "neuroglancer/unstable/ui/default_viewer_setup.js";

setupDefaultViewer();
