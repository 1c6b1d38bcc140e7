"""The twin of radiosity's GPU stages (glsl/radiosity/): the item buffers each hemicube face
draws (`item_buffer.py`)."""
