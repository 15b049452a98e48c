"""What is drawn: plots and animations (matplotlib) and the 3D viewer (three.js, offline). Imports the analysis
layer and below."""
