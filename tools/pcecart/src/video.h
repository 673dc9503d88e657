#ifndef VIDEO_H
#define VIDEO_H

void video_init(void);
void vdc_reg(unsigned char reg, unsigned value);
void vram_seek(unsigned address);
void vram_put(unsigned word);
void set_color(unsigned index, unsigned color);
void bat_put(unsigned char col, unsigned char row, unsigned entry);
void bat_clear(void);
void text(unsigned char col, unsigned char row, const char *s);
void sprite(unsigned char n, int x, int y, unsigned pattern, unsigned attr);
void sprites_hide_from(unsigned char n);
void sprites_flush(void);
void wait_frame(void);
void load_tile(unsigned tile, const char *art);
void load_sprite(unsigned address, const char *art, unsigned char width, unsigned char height);

#endif
